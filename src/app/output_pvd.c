/* solution.pvd: the collection of the load steps written, each step's files of the enabled outputs that are PVD
 * parts (MICA_OUTPUT_PVD_PART: the particles as part 0 and, with output.mesh, the mesh as part 1, in registry
 * order; under MPI a part written in pieces is listed by its .pvtu); ParaView shows a step's parts as blocks of
 * one data set. No setting of its own: written whenever a
 * part wrote a step, also by a solve that failed (its converged steps). Rank 0 writes. */
#include <stdio.h>
#include <stdlib.h>

#include "mica/files.h"
#include "run.h"

enum { NAME_SIZE = 32, MAX_PARTS = 16 };

/* The enabled PVD parts of the run, in registry order; returns their number. */
static int pvd_parts(const MicaOutputRun *run, const MicaOutputOps **parts, int *n) {
  *n = 0;
  for (int i = 0; i < run->noutputs; i++) {
    const MicaOutput *o = &run->outputs[i];
    if (!o->enabled || !mica_type_has(&o->ops->type, MICA_OUTPUT_PVD_PART)) continue;
    MICA_CHECK(*n < MAX_PARTS, MICA_ERR_ARGUMENT, "solution.pvd: more than %d parts", MAX_PARTS);
    parts[(*n)++] = o->ops;
  }
  return MICA_SUCCESS;
}

static int pvd_finish(MicaOutputRun *run, void *ctx, const double *u, MicaJson *summary) {
  (void)ctx, (void)u, (void)summary;
  const MicaOutputOps *parts[MAX_PARTS];
  const char *names[MAX_PARTS];
  int nparts;
  MICA_CALL(pvd_parts(run, parts, &nparts));
  if (nparts == 0 || run->nsteps == 0) return MICA_SUCCESS;
  for (int p = 0; p < nparts; p++) names[p] = parts[p]->part;
  const size_t nfiles = (size_t)run->nsteps * (size_t)nparts;
  char *text = NULL, *path = NULL;
  const char **files = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(text, nfiles * NAME_SIZE));
  MICA_CALL_CLEANUP(MICA_MALLOC(files, nfiles));
  for (size_t i = 0; i < nfiles; i++) {
    files[i] = text + i * NAME_SIZE;
    const MicaOutputOps *part = parts[i % (size_t)nparts];
    const int pieces = run->rp->dist && mica_type_has(&part->type, MICA_OUTPUT_PIECES);
    snprintf(text + i * NAME_SIZE, NAME_SIZE, pieces ? part->pieces_pattern : part->pattern,
             run->steps[i / (size_t)nparts]);
  }
  MICA_CALL_CLEANUP(mica_path_join(mica_output_dir(run), "solution.pvd", &path));
  MICA_CALL_CLEANUP(mica_pvd_write_parts(path, run->nsteps, run->times, nparts, names, files));
cleanup:
  free(path);
  free(files);
  free(text);
  return ierr;
}

const MicaOutputOps run_output_pvd = {
    .type = {"pvd", "the collection of the steps' VTU parts for ParaView (solution.pvd)",
             MICA_OUTPUT_AT_END | MICA_OUTPUT_REACHED | MICA_OUTPUT_RANK0, NULL, NULL},
    .finish = pvd_finish,
};
