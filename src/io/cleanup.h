/* Directories removed when a signal ends the process (cleanup.c): private to src/io. */
#ifndef MICA_IO_CLEANUP_H
#define MICA_IO_CLEANUP_H

/* One directory per process (the staging or scratch directory). On SIGINT, SIGTERM or SIGHUP (those not ignored), path and everything in it is removed, then the
 * signal kills the process as it would have. An absolute path, shorter than PATH_MAX. */
void mica_cleanup_arm(const char *path);
void mica_cleanup_disarm(void);
/* Holds SIGINT, SIGTERM and SIGHUP back (block = 1) or lets a held one through (block = 0): the steps
 * of publication run as one. */
void mica_cleanup_block_signals(int block);

#endif
