/* output.vtu: the fields at the particles after every converged load step, step_NNNN.vtu (each particle a
 * vertex cell), part "particles" of solution.pvd (output_pvd.c). Under MPI each rank writes the piece of its own
 * particles (partition->part), step_NNNN_R.vtu, and rank 0 step_NNNN.pvtu, which lists them; a serial run
 * writes step_NNNN.vtu as before. */
#include <stdio.h>
#include <stdlib.h>

#include "mica/files.h"
#include "run.h"

MICA_SCHEMA_TABLES

static const MicaDeckKey vtu_keys[] = {
    {"vtu", MICA_KEY_BOOL, "true", 1.0, 0.0, NULL, 0, 0, "write particles' fields per load step (VTU + PVD)"},
    {NULL},
};

static int vtu_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options) {
  (void)type;
  return mica_settings_bool(settings, group, "vtu", &((MicaOutput *)options)->enabled);
}

static const char *const piece_pattern = "step_%04d_%d.vtu";

static int vtu_step(MicaOutputRun *run, void *ctx, int step, double t, const double *u) {
  (void)ctx, (void)t;
  const int pieces = run->rp->dist != NULL;
  MicaOutputFields f;
  char name[64], *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(pieces ? run_output_particle_piece(run, u, &f) : mica_output_particle_fields(run, u, &f));
  if (pieces)
    snprintf(name, sizeof name, piece_pattern, step, mica_parallel_rank());
  else
    snprintf(name, sizeof name, run_output_vtu.pattern, step);
  MICA_CALL_CLEANUP(mica_path_join(pieces ? run->piece_dir : mica_output_dir(run), name, &path));
  MICA_CALL_CLEANUP(mica_vtu_write(path, f.dim, f.npoints, f.x, f.nfields, f.fields));
  if (pieces && mica_parallel_rank() == 0) {
    snprintf(name, sizeof name, run_output_vtu.pieces_pattern, step);
    MICA_CALL_CLEANUP(run_output_pvtu(run, name, piece_pattern, step, 0, &f));
  }
cleanup:
  free(path);
  mica_output_fields_free(&f);
  return ierr;
}

const MicaOutputOps run_output_vtu = {
    .type = {"vtu", "the fields at the particles per load step (step_NNNN.vtu; MPI: a piece per rank)",
             MICA_OUTPUT_PER_STEP | MICA_OUTPUT_PVD_PART | MICA_OUTPUT_PIECES, vtu_keys, vtu_from_settings},
    .part = "particles",
    .pattern = "step_%04d.vtu",
    .pieces_pattern = "step_%04d.pvtu",
    .step = vtu_step,
};
