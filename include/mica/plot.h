/* Charts: runs gnuplot on a script the caller wrote into a directory (src/io/plot.c). */
#ifndef MICA_PLOT_H
#define MICA_PLOT_H

#include "mica/error.h"

/* Runs `gnuplot script` with dir as the working directory (the script names its outputs relative to it);
 * gnuplot's messages go to dir/gnuplot.log. switch_off names the deck setting that skips the chart, for
 * the message when gnuplot is missing. */
int mica_gnuplot(const char *dir, const char *script, const char *switch_off);

#endif
