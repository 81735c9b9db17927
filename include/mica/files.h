/* Output files that are either complete or absent: written to DIR/.name.tmp, renamed on commit. A run
 * that fails leaves every file it had already written untouched and no half-written one. */
#ifndef MICA_FILES_H
#define MICA_FILES_H

#include <stdio.h>

#include "mica/error.h"

typedef struct MicaOutFile {
  FILE *fp;          /* write here */
  char *path;        /* final path */
  char *tmp_path;    /* where the data goes until commit */
} MicaOutFile;

/* mkdir -p */
int mica_make_dir(const char *dir);
int mica_out_open(const char *path, MicaOutFile *out);
/* mica_out_open of dir/name (the file keeps its own copy of the path). */
int mica_out_open_in(const char *dir, const char *name, MicaOutFile *out);
/* Flushes, checks for write errors, renames into place. */
int mica_out_commit(MicaOutFile *out);
/* Removes the temporary file; safe to call after commit or on a file never opened. */
void mica_out_abort(MicaOutFile *out);
/* dir + "/" + name into a new string. */
int mica_path_join(const char *dir, const char *name, char **path);

/* rm -r path (a file, or a directory and everything in it); what cannot be removed stays. */
void mica_remove_tree(const char *path);

#endif
