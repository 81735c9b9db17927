/* Charts: runs gnuplot on a script the caller wrote into a directory (src/io/plot.c). */
#ifndef MICA_PLOT_H
#define MICA_PLOT_H

#include <stddef.h>

#include "mica/error.h"

/* Runs `gnuplot script` with dir as the working directory (the script names its outputs relative to it);
 * gnuplot's messages go to dir/gnuplot.log. switch_off names the deck setting that skips the chart, for
 * the message when gnuplot is missing. */
int mica_gnuplot(const char *dir, const char *script, const char *switch_off);

/* A label (variant name, choice, legend) made safe for a quoted gnuplot string: quotes and backslashes
 * become spaces; out holds at most size − 1 characters. */
void mica_gnuplot_label(const char *in, char *out, size_t size);

#endif
