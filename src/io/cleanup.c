/* Removal of the staging directory when SIGINT, SIGTERM or SIGHUP ends the process (cleanup.h). The
 * handler may interrupt anything, a factorization or a malloc, so it uses only system calls: the paths
 * were copied into static buffers beforehand, and the tree is walked with openat/getdents64/unlinkat on
 * stack buffers. Then the signal is raised again with its default action, so the exit status says which
 * signal ended the run. */
#define _GNU_SOURCE
#include "cleanup.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <string.h>
#include <sys/syscall.h>
#include <unistd.h>

static const int cleanup_signals[] = {SIGINT, SIGTERM, SIGHUP};
enum { NSIGNALS = sizeof cleanup_signals / sizeof cleanup_signals[0], MAX_DEPTH = 16 };

static char armed_path[PATH_MAX];
static volatile sig_atomic_t armed;
static int installed;
/* While publication runs, a signal is held here (a thread other than the blocked main one may take it). */
static volatile sig_atomic_t holding, held;

struct dirent64_record { /* what getdents64 fills in */
  unsigned long long ino;
  long long off;
  unsigned short reclen;
  unsigned char type;
  char name[];
};

/* rm -r of name in the directory parent, with system calls only. Entries removed while the directory is
 * read may make getdents skip some, so the directory is read again until it is empty (or no progress). */
static void remove_at(int parent, const char *name, int depth) {
  if (unlinkat(parent, name, 0) == 0 || (errno != EISDIR && errno != EPERM)) return;
  int fd = openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  for (int pass = 0; pass < 4 && depth < MAX_DEPTH; pass++) {
    char buffer[4096];
    long n, removed = 0;
    lseek(fd, 0, SEEK_SET);
    while ((n = syscall(SYS_getdents64, fd, buffer, sizeof buffer)) > 0) {
      for (long at = 0; at < n;) {
        struct dirent64_record *entry = (struct dirent64_record *)(buffer + at);
        at += entry->reclen;
        if (!strcmp(entry->name, ".") || !strcmp(entry->name, "..")) continue;
        remove_at(fd, entry->name, depth + 1);
        removed++;
      }
    }
    if (!removed) break;
  }
  close(fd);
  unlinkat(parent, name, AT_REMOVEDIR);
}

static void clean_and_die(int sig) {
  if (armed) remove_at(AT_FDCWD, armed_path, 0);
  /* SA_RESETHAND restored the default action: the raised signal ends the process once the handler
   * returns and the signal is unblocked */
  raise(sig);
}

static void on_signal(int sig) {
  const int saved = errno;
  if (holding)
    held = sig;
  else
    clean_and_die(sig);
  errno = saved;
}

/* Installed once, and only for signals whose action is the default: a run under nohup keeps ignoring
 * SIGHUP. */
static void install(void) {
  if (installed) return;
  installed = 1;
  for (int i = 0; i < NSIGNALS; i++) {
    struct sigaction now, action;
    if (sigaction(cleanup_signals[i], NULL, &now) != 0 || now.sa_handler != SIG_DFL) continue;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_signal;
    action.sa_flags = SA_RESETHAND;
    sigfillset(&action.sa_mask); /* one cleanup at a time */
    sigaction(cleanup_signals[i], &action, NULL);
  }
}

void mica_cleanup_arm(const char *path) {
  if (strlen(path) >= PATH_MAX) return;
  install();
  armed = 0;
  memcpy(armed_path, path, strlen(path) + 1);
  armed = 1;
}

void mica_cleanup_disarm(void) { armed = 0; }

void mica_cleanup_block_signals(int block) {
  sigset_t set;
  sigemptyset(&set);
  for (int i = 0; i < NSIGNALS; i++) sigaddset(&set, cleanup_signals[i]);
  if (block) {
    sigprocmask(SIG_BLOCK, &set, NULL);
    holding = 1;
    return;
  }
  holding = 0;
  if (held) clean_and_die(held);
  sigprocmask(SIG_UNBLOCK, &set, NULL);
}
