/* `mica check`: a run deck read, checked and built like `mica run` (run_problem_prepare), and its cost class;
 * nothing is solved. */
#include <stdio.h>
#include <string.h>

#include "run.h"

static int run_check(const MicaDeck *deck, const char *outdir, MicaJson *summary) {
  RunProblem rp;
  RunOutput out; /* read and checked only: nothing is written */
  RunTotals totals;
  int ierr = MICA_SUCCESS;
  memset(&out, 0, sizeof out);
  MICA_CALL_CLEANUP(run_problem_prepare(deck, &rp, NULL, outdir, &out, &totals, summary));
  const double nnz = (double)totals.nnz;
  const char *size_class = nnz < 1e6 ? "small (seconds)" : nnz < 3e7 ? "medium (minutes)" : "large (hours, or use MPI)";
  MICA_CALL_CLEANUP(mica_json_string(summary, "cost_class", size_class));
  MICA_CALL_CLEANUP(run_build_memory(&rp, summary));
  printf("deck is valid; cost class: %s\n", size_class);
cleanup:
  run_output_free(&out);
  run_problem_free(&rp);
  return ierr;
}

const MicaCommand mica_command_check = {
    {"check",
     "validate a run deck and print its cost (particles, quadrature points, dofs, nnz, memory) without solving",
     0, NULL, NULL},
    "Reads and checks the deck like `mica run`, builds the discretization, shape-function cache and sparsity\n"
    "pattern, and reports their sizes and a cost class. Nothing is solved.",
    mica_run_schema,
    run_check,
};
