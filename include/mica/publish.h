/* Results published whole (src/io/publish.c). A run writes into a staging directory beside the output
 * directory DIR, PARENT/.NAME.staging-HOST-PID, and publishes it with one rename(2) that swaps it with DIR
 * (renameat2 RENAME_EXCHANGE): a reader sees the old results or the new ones, never a mix, and nothing of
 * an earlier run is left among the new ones. mica replaces only what it wrote: DIR must be absent, empty,
 * or a directory it published before (its list of files, DIR/.mica-results, covers everything in it).
 * SIGINT, SIGTERM and SIGHUP remove the staging directory before the process dies; the staging
 * directories of processes killed outright (SIGKILL) are removed by the next run into the same place.
 * Ranks other than 0 of a parallel run write into a scratch directory under $TMPDIR, cleaned the same way. */
#ifndef MICA_PUBLISH_H
#define MICA_PUBLISH_H

#include "mica/error.h"

typedef struct MicaStaging MicaStaging;

/* Rank 0 (and serial runs): checks that outdir may be replaced (MICA_ERR_INPUT if not, saying why),
 * removes stale staging directories beside it, makes the staging directory and arms its removal on a
 * signal. */
int mica_staging_create_results(const char *outdir, MicaStaging **staging);
/* Ranks other than 0: a scratch directory $TMPDIR/mica-rankRANK-HOST-PID, cleaned the same way. */
int mica_staging_create_scratch(int rank, MicaStaging **staging);
/* Where the command writes. */
const char *mica_staging_dir(const MicaStaging *staging);
/* Writes the list of files and swaps the staging directory in as outdir (results only). */
int mica_staging_publish(MicaStaging *staging);
/* Removes the staging directory if it was not published (and the old results if they are still there);
 * disarms the signal cleanup. */
void mica_staging_destroy(MicaStaging **staging);

#endif
