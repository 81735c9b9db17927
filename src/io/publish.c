/* Results published whole (publish.h). The staging directory is a sibling of the output directory, so the
 * swap is one rename(2) within one file system; its name carries the host and the process id, so a later
 * run can tell a staging directory whose process is gone (killed outright) from one still in use. */
#define _GNU_SOURCE
#include "mica/publish.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cleanup.h"
#include "mica/files.h"

/* The list of what mica wrote, kept in the published directory: what the next run may replace. */
#define MANIFEST ".mica-results"

struct MicaStaging {
  char *dir;      /* where the command writes */
  char *outdir;   /* absolute output directory (NULL for a scratch directory) */
  char *shown;    /* outdir as the user wrote it, for messages */
  int published;
};

typedef struct {
  char **item;
  size_t n, cap;
} NameList;

static void names_free(NameList *list) {
  for (size_t i = 0; i < list->n; i++) free(list->item[i]);
  MICA_FREE(list->item);
  list->n = list->cap = 0;
}

static int names_add(NameList *list, const char *name) {
  if (list->n == list->cap) {
    list->cap = list->cap ? 2 * list->cap : 64;
    MICA_CALL(MICA_REALLOC(list->item, list->cap));
  }
  MICA_CALL(MICA_MALLOC(list->item[list->n], strlen(name) + 1));
  strcpy(list->item[list->n++], name);
  return MICA_SUCCESS;
}

static int compare_names(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static int names_have(const NameList *list, const char *name) {
  return list->n && bsearch(&name, list->item, list->n, sizeof *list->item, compare_names) != NULL;
}

static int copy_string(const char *text, char **copy) {
  MICA_CALL(MICA_MALLOC(*copy, strlen(text) + 1));
  strcpy(*copy, text);
  return MICA_SUCCESS;
}

/* ---- what a directory holds ------------------------------------------------------------------------- */

/* Every entry under root/rel, as paths relative to root (directories end in '/'), the list aside. */
static int list_tree(const char *root, const char *rel, NameList *list) {
  char *path = NULL;
  MICA_CALL(mica_path_join(root, rel, &path));
  DIR *dir = opendir(path);
  free(path);
  MICA_CHECK(dir, MICA_ERR_IO, "cannot read the directory %s/%s: %s", root, rel, strerror(errno));
  int ierr = MICA_SUCCESS;
  struct dirent *entry;
  while (!ierr && (entry = readdir(dir))) {
    if (!strcmp(entry->d_name, ".") || !strcmp(entry->d_name, "..") || !strcmp(entry->d_name, MANIFEST))
      continue;
    char name[PATH_MAX];
    struct stat info;
    snprintf(name, sizeof name, "%s%s", rel, entry->d_name);
    ierr = mica_path_join(root, name, &path);
    const int is_dir = !ierr && lstat(path, &info) == 0 && S_ISDIR(info.st_mode);
    free(path);
    if (is_dir) strncat(name, "/", sizeof name - strlen(name) - 1);
    if (!ierr) ierr = names_add(list, name);
    if (!ierr && is_dir) ierr = list_tree(root, name, list);
  }
  closedir(dir);
  return ierr;
}

/* The names in dir/.mica-results, sorted; *found = 0 (and an empty list) if there is none. */
static int read_manifest(const char *dir, NameList *list, int *found) {
  char *path = NULL, line[PATH_MAX + 2];
  MICA_CALL(mica_path_join(dir, MANIFEST, &path));
  FILE *fp = fopen(path, "r");
  free(path);
  *found = fp != NULL;
  int ierr = MICA_SUCCESS;
  while (fp && !ierr && fgets(line, sizeof line, fp)) {
    line[strcspn(line, "\n")] = '\0';
    if (line[0] && line[0] != '#') ierr = names_add(list, line);
  }
  if (fp) fclose(fp);
  if (list->n) qsort(list->item, list->n, sizeof *list->item, compare_names);
  return ierr;
}

static int write_manifest(const char *dir) {
  NameList list = {0};
  MicaOutFile out;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(list_tree(dir, "", &list));
  qsort(list.item, list.n, sizeof *list.item, compare_names);
  MICA_CALL_CLEANUP(mica_out_open_in(dir, MANIFEST, &out));
  fprintf(out.fp, "# written by mica: the files of these results. The next run into this directory replaces "
                  "it whole,\n# which mica does only while it holds nothing but these.\n");
  for (size_t i = 0; i < list.n; i++) fprintf(out.fp, "%s\n", list.item[i]);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  names_free(&list);
  return ierr;
}

/* ---- may the output directory be replaced? ---------------------------------------------------------- */

/* The working directory inside outdir would be deleted under the user's feet. */
static int check_not_cwd(const char *outdir, const char *shown) {
  char cwd[PATH_MAX];
  const size_t n = strlen(outdir);
  if (!getcwd(cwd, sizeof cwd)) return MICA_SUCCESS;
  MICA_CHECK(strncmp(cwd, outdir, n) || (cwd[n] != '\0' && cwd[n] != '/' && strcmp(outdir, "/")), MICA_ERR_INPUT,
             "-o %s: the output directory is the working directory or holds it; mica replaces the output "
             "directory whole when it publishes the results, so give it one of its own (e.g. -o out/run1)",
             shown);
  return MICA_SUCCESS;
}

/* outdir must be absent, empty, or hold only what the previous run's list names. */
static int check_replaceable(const char *outdir, const char *shown) {
  struct stat info;
  if (stat(outdir, &info) != 0) return MICA_SUCCESS;
  MICA_CHECK(S_ISDIR(info.st_mode), MICA_ERR_INPUT, "-o %s: a file of that name exists; give a directory", shown);
  MICA_CALL(check_not_cwd(outdir, shown));
  NameList present = {0}, written = {0};
  int ierr = MICA_SUCCESS, found = 0;
  MICA_CALL_CLEANUP(list_tree(outdir, "", &present));
  MICA_CALL_CLEANUP(read_manifest(outdir, &written, &found));
  for (size_t i = 0; i < present.n; i++) {
    if (names_have(&written, present.item[i])) continue;
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                          "-o %s: the directory holds '%s', which mica did not write there%s; mica replaces "
                          "the output directory whole, so move that away or choose another directory",
                          shown, present.item[i], found ? "" : " (it has no " MANIFEST " list of results)");
    goto cleanup;
  }
cleanup:
  names_free(&present);
  names_free(&written);
  return ierr;
}

/* ---- names: PREFIX HOST-PID ------------------------------------------------------------------------- */

static void host_name(char *host, size_t size) {
  if (gethostname(host, size) != 0) snprintf(host, size, "localhost");
  host[size - 1] = '\0';
  for (char *c = host; *c; c++)
    if (*c == '/') *c = '_';
}

/* The process id in "HOST-PID" if HOST is this host, else 0. */
static long owner_on_this_host(const char *rest, const char *host) {
  const size_t n = strlen(host);
  if (strncmp(rest, host, n) || rest[n] != '-' || !rest[n + 1]) return 0;
  char *end;
  const long pid = strtol(rest + n + 1, &end, 10);
  return *end || pid <= 0 ? 0 : pid;
}

/* Removes dir/name if the process that made it is gone. A lock on it lets one of several processes
 * (the ranks on one host) remove it and say so. */
static void remove_if_dead(const char *dir, const char *name, long pid, const char *who) {
  const int reused = pid == (long)getpid(); /* an earlier process had our id: it is gone */
  if (!reused && (kill((pid_t)pid, 0) == 0 || errno != ESRCH)) return; /* alive, or not ours to ask */
  char *path = NULL;
  if (mica_path_join(dir, name, &path)) return;
  const int fd = open(path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  struct stat held, now;
  if (fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0 && fstat(fd, &held) == 0 && lstat(path, &now) == 0 &&
      held.st_ino == now.st_ino && held.st_dev == now.st_dev) {
    mica_remove_tree(path);
    fprintf(stderr, "mica: %sremoved %s, left by process %ld, which is no longer running\n", who, path, pid);
  }
  if (fd >= 0) close(fd);
  free(path);
}

/* Removes the entries of dir named prefix + "HOST-PID" (after skipping digits if skip_digits: the rank)
 * whose process on this host is gone. */
static void remove_stale(const char *dir, const char *prefix, int skip_digits, const char *who) {
  char host[256];
  host_name(host, sizeof host);
  DIR *d = opendir(dir);
  struct dirent *entry;
  const size_t n = strlen(prefix);
  while (d && (entry = readdir(d))) {
    if (strncmp(entry->d_name, prefix, n)) continue;
    const char *rest = entry->d_name + n;
    if (skip_digits) {
      rest += strspn(rest, "0123456789");
      if (*rest++ != '-') continue;
    }
    const long pid = owner_on_this_host(rest, host);
    if (pid) remove_if_dead(dir, entry->d_name, pid, who);
  }
  if (d) closedir(d);
}

/* dir/prefix + "HOST-PID", made afresh (a leftover of an earlier process with this id is removed). */
static int make_named_dir(const char *dir, const char *prefix, char **path) {
  char host[256], name[NAME_MAX + 1];
  host_name(host, sizeof host);
  MICA_CHECK(snprintf(name, sizeof name, "%s%s-%ld", prefix, host, (long)getpid()) < (int)sizeof name,
             MICA_ERR_INPUT, "the output directory's name is too long for a staging directory beside it: %s", prefix);
  MICA_CALL(mica_path_join(dir, name, path));
  mica_remove_tree(*path);
  MICA_CHECK(mkdir(*path, 0777) == 0, MICA_ERR_IO, "cannot create the staging directory %s: %s", *path,
             strerror(errno));
  return MICA_SUCCESS;
}

/* ---- the output directory as an absolute path ------------------------------------------------------- */

/* outdir resolved (., .., symbolic links) to an absolute path; its parent is made if missing. */
static int absolute_outdir(const char *outdir, char **absolute) {
  char resolved[PATH_MAX], *copy = NULL;
  if (realpath(outdir, resolved)) return copy_string(resolved, absolute);
  MICA_CHECK(errno == ENOENT, MICA_ERR_IO, "-o %s: %s", outdir, strerror(errno));
  MICA_CALL(copy_string(outdir, &copy));
  for (size_t n = strlen(copy); n > 1 && copy[n - 1] == '/'; n--) copy[n - 1] = '\0';
  char *slash = strrchr(copy, '/');
  const char *base = slash ? slash + 1 : copy;
  int ierr = MICA_SUCCESS;
  if (!strcmp(base, ".") || !strcmp(base, "..")) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "-o %s: no such directory", outdir);
    goto cleanup;
  }
  if (slash) *slash = '\0';
  const char *parent = slash ? (copy[0] ? copy : "/") : ".";
  MICA_CALL_CLEANUP(mica_make_dir(parent));
  if (!realpath(parent, resolved)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "-o %s: %s", outdir, strerror(errno));
    goto cleanup;
  }
  MICA_CALL_CLEANUP(mica_path_join(resolved, base, absolute));
cleanup:
  free(copy);
  return ierr;
}

/* The parent of an absolute path (a new string) and its last name (inside path). */
static int split_path(const char *path, char **parent, const char **base) {
  const char *slash = strrchr(path, '/');
  const size_t n = slash == path ? 1 : (size_t)(slash - path);
  MICA_CALL(MICA_MALLOC(*parent, n + 1));
  memcpy(*parent, path, n);
  (*parent)[n] = '\0';
  *base = slash + 1;
  return MICA_SUCCESS;
}

/* ---- create, publish, destroy ----------------------------------------------------------------------- */

static int staging_new(MicaStaging **staging) {
  MICA_CALL(MICA_CALLOC(*staging, 1));
  return MICA_SUCCESS;
}

int mica_staging_create_results(const char *outdir, MicaStaging **staging) {
  MICA_CHECK(outdir && staging, MICA_ERR_ARGUMENT, "mica_staging_create_results: NULL argument");
  char *parent = NULL;
  const char *base;
  int ierr = MICA_SUCCESS;
  MICA_CALL(staging_new(staging));
  MicaStaging *s = *staging;
  MICA_CALL_CLEANUP(copy_string(outdir, &s->shown));
  MICA_CALL_CLEANUP(absolute_outdir(outdir, &s->outdir));
  if (!strcmp(s->outdir, "/")) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "-o %s: the root directory cannot "
                          "hold results", outdir);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(check_replaceable(s->outdir, outdir));
  MICA_CALL_CLEANUP(split_path(s->outdir, &parent, &base));
  char prefix[NAME_MAX + 32];
  snprintf(prefix, sizeof prefix, ".%s.old-", base);
  remove_stale(parent, prefix, 0, "");
  snprintf(prefix, sizeof prefix, ".%s.staging-", base);
  remove_stale(parent, prefix, 0, "");
  MICA_CALL_CLEANUP(make_named_dir(parent, prefix, &s->dir));
  mica_cleanup_arm(s->dir);
cleanup:
  free(parent);
  if (ierr) mica_staging_destroy(staging);
  return ierr;
}

int mica_staging_create_scratch(int rank, MicaStaging **staging) {
  MICA_CHECK(staging, MICA_ERR_ARGUMENT, "mica_staging_create_scratch: NULL argument");
  const char *tmp = getenv("TMPDIR");
  char *dir = NULL, prefix[64], who[64];
  int ierr = MICA_SUCCESS;
  MICA_CALL(staging_new(staging));
  MICA_CALL_CLEANUP(absolute_outdir(tmp && *tmp ? tmp : "/tmp", &dir));
  snprintf(who, sizeof who, "rank %d: ", rank);
  remove_stale(dir, "mica-rank", 1, who);
  snprintf(prefix, sizeof prefix, "mica-rank%d-", rank);
  MICA_CALL_CLEANUP(make_named_dir(dir, prefix, &(*staging)->dir));
  mica_cleanup_arm((*staging)->dir);
cleanup:
  free(dir);
  if (ierr) mica_staging_destroy(staging);
  return ierr;
}

const char *mica_staging_dir(const MicaStaging *staging) { return staging ? staging->dir : NULL; }

/* The old results go to PARENT/.NAME.old-HOST-PID and the new ones in: two renames, for file systems
 * without RENAME_EXCHANGE. A reader who looks between the two finds no results. */
static int swap_in_two_steps(MicaStaging *s) {
  char *parent = NULL, *old = NULL;
  const char *base;
  int ierr = MICA_SUCCESS;
  char prefix[NAME_MAX + 32];
  MICA_CALL_CLEANUP(split_path(s->outdir, &parent, &base));
  snprintf(prefix, sizeof prefix, ".%s.old-", base);
  MICA_CALL_CLEANUP(make_named_dir(parent, prefix, &old));
  rmdir(old);
  if (rename(s->outdir, old) != 0 || rename(s->dir, s->outdir) != 0) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "cannot publish %s: %s", s->shown,
                          strerror(errno));
    rename(old, s->outdir); /* back, if it had moved */
    goto cleanup;
  }
  rename(old, s->dir); /* where the old results are removed from */
cleanup:
  free(parent);
  free(old);
  return ierr;
}

/* One rename: the staging directory becomes outdir; the old results (if any) take its name. */
static int swap_in(MicaStaging *s) {
  struct stat info;
  if (stat(s->outdir, &info) != 0) {
    MICA_CHECK(rename(s->dir, s->outdir) == 0, MICA_ERR_IO, "cannot publish %s: %s", s->shown, strerror(errno));
    return MICA_SUCCESS;
  }
  if (renameat2(AT_FDCWD, s->dir, AT_FDCWD, s->outdir, RENAME_EXCHANGE) == 0) return MICA_SUCCESS;
  MICA_CHECK(errno == EINVAL || errno == ENOSYS, MICA_ERR_IO, "cannot publish %s: %s", s->shown, strerror(errno));
  return swap_in_two_steps(s);
}

int mica_staging_publish(MicaStaging *staging) {
  MICA_CHECK(staging && staging->outdir && !staging->published, MICA_ERR_ARGUMENT,
             "mica_staging_publish: not an unpublished results directory");
  MICA_CALL(write_manifest(staging->dir));
  mica_cleanup_block_signals(1);
  int ierr = check_replaceable(staging->outdir, staging->shown); /* again: the run may have been long */
  if (!ierr) ierr = swap_in(staging);
  staging->published = !ierr;
  mica_cleanup_block_signals(0); /* a signal from now on removes the old results, as below */
  if (staging->published) mica_remove_tree(staging->dir);
  mica_cleanup_disarm();
  return ierr;
}

void mica_staging_destroy(MicaStaging **staging) {
  if (!staging || !*staging) return;
  MicaStaging *s = *staging;
  if (s->dir) mica_remove_tree(s->dir); /* unpublished, or the old results after publication */
  mica_cleanup_disarm();
  free(s->dir);
  free(s->outdir);
  free(s->shown);
  MICA_FREE(*staging);
}
