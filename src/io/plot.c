/* Charts through gnuplot: a child process in the output directory, its messages in gnuplot.log. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "mica/plot.h"

int mica_gnuplot(const char *dir, const char *script, const char *switch_off) {
  fflush(stdout); /* the child must not repeat buffered output */
  pid_t pid = fork();
  MICA_CHECK(pid >= 0, MICA_ERR_LIBRARY, "cannot start gnuplot: %s", strerror(errno));
  if (pid == 0) {
    if (chdir(dir) != 0) _exit(126);
    FILE *log = freopen("gnuplot.log", "w", stderr);
    (void)log;
    execlp("gnuplot", "gnuplot", script, (char *)NULL);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  MICA_CHECK(WIFEXITED(status) && WEXITSTATUS(status) != 127, MICA_ERR_LIBRARY,
             "gnuplot is not installed: run `make deps` (package gnuplot-nox), or set %s = false", switch_off);
  MICA_CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, MICA_ERR_LIBRARY,
             "gnuplot failed drawing the chart (exit %d); see gnuplot.log in the output directory",
             WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  return MICA_SUCCESS;
}

void mica_gnuplot_label(const char *in, char *out, size_t size) {
  size_t j = 0;
  for (size_t i = 0; in[i] && j + 1 < size; i++) out[j++] = (in[i] == '"' || in[i] == '\\' || in[i] == '\'') ? ' ' : in[i];
  out[j] = '\0';
}
