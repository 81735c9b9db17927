/* Charts: runs gnuplot on a script the caller wrote into a directory (src/io/plot.c). */
#ifndef MICA_PLOT_H
#define MICA_PLOT_H

#include <stddef.h>
#include <stdio.h>

#include "mica/error.h"

/* Runs `gnuplot script` with dir as the working directory (the script names its outputs relative to it);
 * gnuplot's messages go to dir/gnuplot.log. switch_off names the deck setting that skips the chart, for
 * the message when gnuplot is missing. */
int mica_gnuplot(const char *dir, const char *script, const char *switch_off);

/* Text (a deck string: title, variant, choice or probe name, label) as a single-quoted gnuplot string,
 * quotes included: the one way text enters a chart script, so that it is printed as written and never run
 * (gnuplot 5.4 expands no backquote, @macro or backslash inside single quotes; a quote is doubled; control
 * characters, which would end the command, become spaces). Every chart's terminal is `noenhanced`, so
 * ^ _ @ & ~ { } \ print as themselves. Truncated to size bytes between characters. */
void mica_gnuplot_quote(const char *in, char *out, size_t size);
/* The same text as a double-quoted field of a gnuplot data file (read by `with labels`): \" and \\. */
void mica_gnuplot_datum(const char *in, char *out, size_t size);
/* An identifier shown as words, not quoted: "a_over_l" -> "a over l". */
void mica_gnuplot_words(const char *in, char *out, size_t size);

/* Series styles, one palette for every chart (docs/input.md §Charts): Okabe & Ito's seven colours that stay
 * apart for colour-blind readers (black is left for references and marks), solid lines for the first seven
 * series, dash-dot for the next seven, dash-dot-dot for the seven after, each series with its own point type
 * (15 kinds); series k and k + MICA_GNUPLOT_SERIES look alike. */
enum { MICA_GNUPLOT_SERIES = 21 };
const char *mica_gnuplot_colour(int k); /* "#0072B2" */
/* "lc rgb '#0072B2' dt 1 pt 7" for series k (lines with points). */
void mica_gnuplot_series(int k, char *out, size_t size);
/* "lc rgb '#0072B2' dt 1" for series k drawn as lines only. */
void mica_gnuplot_line(int k, char *out, size_t size);

/* Writes `set key` for a key outside the plot area, below it, `columns` entries a row, with the bottom margin
 * it needs (gnuplot's own `set key below` lets the key's box run over the x label). Returns the rows, for
 * the canvas height. */
int mica_gnuplot_key_below(FILE *fp, int nentries, int columns);
/* Writes `set Xrange` (axis 'x' or 'y') to [lo, hi] widened by a margin of `margin` of the span (of the
 * decades on a log axis), so that no curve or reference line lies on the border; on a log axis spanning
 * less than three decades, also tics at 2 and 5 (or 1.5, 2, 3, 5, 7 under one decade) times the powers of 10,
 * where gnuplot would label the decades only. */
void mica_gnuplot_range(FILE *fp, char axis, double lo, double hi, int logscale, double margin);
/* How many columns of entries whose longest title has `longest` characters fit across `width` pixels (at
 * most maxcols, at least 1; generous per character, so that gnuplot never needs more rows than counted). */
int mica_gnuplot_key_columns(int width, size_t longest, int maxcols);
/* The rows such a key takes. */
int mica_gnuplot_key_rows(int nentries, int columns);

#endif
