/* Output files that are complete or absent (files.h): data goes to DIR/.name.tmp and is renamed into
 * place only after every byte was written, so a failed run never leaves a half-written result behind. */
#include "mica/files.h"

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

static int copy_string(const char *text, char **copy) {
  MICA_CALL(MICA_MALLOC(*copy, strlen(text) + 1));
  memcpy(*copy, text, strlen(text) + 1);
  return MICA_SUCCESS;
}

/* Creates one directory; an existing directory is fine, an existing file of that name is not. */
static int make_one_dir(const char *dir) {
  if (mkdir(dir, 0777) == 0) return MICA_SUCCESS;
  int saved = errno;
  struct stat info;
  if (saved == EEXIST && stat(dir, &info) == 0 && S_ISDIR(info.st_mode)) return MICA_SUCCESS;
  if (saved == EEXIST) MICA_ERROR(MICA_ERR_IO, "cannot create directory '%s': a file of that name exists", dir);
  MICA_ERROR(MICA_ERR_IO, "cannot create directory '%s': %s", dir, strerror(saved));
}

int mica_make_dir(const char *dir) {
  MICA_CHECK(dir, MICA_ERR_ARGUMENT, "mica_make_dir: dir is NULL");
  if (!dir[0]) return MICA_SUCCESS;
  char *partial = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(copy_string(dir, &partial));
  /* Create each ancestor in turn: cut the path after every separator but a leading one. */
  for (char *sep = strchr(partial + 1, '/'); sep; sep = strchr(sep + 1, '/')) {
    *sep = '\0';
    MICA_CALL_CLEANUP(make_one_dir(partial));
    *sep = '/';
  }
  MICA_CALL_CLEANUP(make_one_dir(partial));
cleanup:
  free(partial);
  return ierr;
}

int mica_path_join(const char *dir, const char *name, char **path) {
  MICA_CHECK(dir && name && path, MICA_ERR_ARGUMENT, "mica_path_join: NULL argument");
  size_t dir_len = strlen(dir), name_len = strlen(name);
  int needs_slash = dir_len > 0 && dir[dir_len - 1] != '/';
  MICA_CALL(MICA_MALLOC(*path, dir_len + (size_t)needs_slash + name_len + 1));
  memcpy(*path, dir, dir_len);
  if (needs_slash) (*path)[dir_len] = '/';
  memcpy(*path + dir_len + needs_slash, name, name_len + 1);
  return MICA_SUCCESS;
}

/* DIR/.name.tmp for DIR/name: same directory, so the final rename cannot cross file systems. */
static int temporary_path(const char *path, char **tmp_path) {
  const char *slash = strrchr(path, '/');
  size_t dir_len = slash ? (size_t)(slash - path) + 1 : 0;
  const char *name = path + dir_len;
  size_t name_len = strlen(name);
  MICA_CALL(MICA_MALLOC(*tmp_path, dir_len + name_len + sizeof "..tmp"));
  memcpy(*tmp_path, path, dir_len);
  (*tmp_path)[dir_len] = '.';
  memcpy(*tmp_path + dir_len + 1, name, name_len);
  memcpy(*tmp_path + dir_len + 1 + name_len, ".tmp", sizeof ".tmp");
  return MICA_SUCCESS;
}

int mica_out_open(const char *path, MicaOutFile *out) {
  MICA_CHECK(path && out, MICA_ERR_ARGUMENT, "mica_out_open: NULL argument");
  *out = (MicaOutFile){NULL, NULL, NULL};
  MICA_CHECK(path[0] && path[strlen(path) - 1] != '/', MICA_ERR_ARGUMENT,
             "mica_out_open: '%s' is not a file name", path);
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(copy_string(path, &out->path));
  MICA_CALL_CLEANUP(temporary_path(path, &out->tmp_path));
  out->fp = fopen(out->tmp_path, "w");
  if (!out->fp) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot write '%s': %s", path,
                          strerror(errno));
    goto cleanup;
  }
  return MICA_SUCCESS;
cleanup:
  mica_out_abort(out);
  return ierr;
}

int mica_out_open_in(const char *dir, const char *name, MicaOutFile *out) {
  char *path = NULL;
  MICA_CALL(mica_path_join(dir, name, &path));
  const int ierr = mica_out_open(path, out);
  free(path);
  return ierr;
}

/* Frees the names once the file is committed or abandoned, so a second commit or abort is harmless. */
static void forget(MicaOutFile *out) {
  MICA_FREE(out->path);
  MICA_FREE(out->tmp_path);
  out->fp = NULL;
}

int mica_out_commit(MicaOutFile *out) {
  MICA_CHECK(out && out->fp, MICA_ERR_ARGUMENT, "mica_out_commit: the file is not open");
  /* A full disk shows up in fflush, in the stream's error flag, or only in fclose: check all three. */
  int failed = fflush(out->fp) != 0 || ferror(out->fp);
  int saved = errno;
  if (fclose(out->fp) != 0 && !failed) {
    failed = 1;
    saved = errno;
  }
  out->fp = NULL;
  if (!failed && rename(out->tmp_path, out->path) != 0) {
    failed = 1;
    saved = errno;
  }
  if (failed) {
    int code = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot write '%s': %s",
                              out->path, strerror(saved));
    mica_out_abort(out);
    return code;
  }
  forget(out);
  return MICA_SUCCESS;
}

void mica_out_abort(MicaOutFile *out) {
  if (!out) return;
  if (out->fp) fclose(out->fp);
  if (out->tmp_path) unlink(out->tmp_path);
  forget(out);
}

void mica_remove_tree(const char *path) {
  struct stat info;
  if (lstat(path, &info) != 0) return;
  if (!S_ISDIR(info.st_mode)) {
    unlink(path);
    return;
  }
  DIR *dir = opendir(path);
  struct dirent *entry;
  while (dir && (entry = readdir(dir))) {
    if (!strcmp(entry->d_name, ".") || !strcmp(entry->d_name, "..")) continue;
    char *child = NULL;
    if (mica_path_join(path, entry->d_name, &child) == MICA_SUCCESS) mica_remove_tree(child);
    free(child);
  }
  if (dir) closedir(dir);
  rmdir(path);
}
