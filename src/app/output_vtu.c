/* output.vtu: the fields at the particles after every converged load step, step_NNNN.vtu (each particle a
 * vertex cell), part "particles" of solution.pvd (output_pvd.c). Rank 0 writes: the solution is whole on every
 * rank. */
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

static int vtu_step(MicaOutputRun *run, void *ctx, int step, double t, const double *u) {
  (void)ctx, (void)t;
  MicaOutputFields f;
  char name[32], *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(mica_output_particle_fields(run, u, &f));
  snprintf(name, sizeof name, run_output_vtu.pattern, step);
  MICA_CALL_CLEANUP(mica_path_join(mica_output_dir(run), name, &path));
  MICA_CALL_CLEANUP(mica_vtu_write(path, f.dim, f.npoints, f.x, f.nfields, f.fields));
cleanup:
  free(path);
  mica_output_fields_free(&f);
  return ierr;
}

const MicaOutputOps run_output_vtu = {
    .type = {"vtu", "the fields at the particles per load step (step_NNNN.vtu)",
             MICA_OUTPUT_PER_STEP | MICA_OUTPUT_RANK0 | MICA_OUTPUT_PVD_PART, vtu_keys, vtu_from_settings},
    .part = "particles",
    .pattern = "step_%04d.vtu",
    .step = vtu_step,
};
