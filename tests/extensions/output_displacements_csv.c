/* An output type added from outside the program (issue 18: adding a type is one file): with
 * `output.displacements_csv = true`, displacements.csv after the solve, one row per particle: its coordinates and
 * the displacement there (the VTU files' "displacement" field, through mica_output_particle_fields), every number
 * with 17 significant digits. Linked into build/tests/mica-ext only; it registers itself before main, and its key
 * then appears in the run schema, `mica help run` and the deck checks. The unit tests' _ext variants do not link
 * it: it uses the application layer (the Makefile's EXT_APP_SRC). */
#include <stdio.h>
#include <stdlib.h>

#include "mica/files.h"
#include "mica/output.h"

static const MicaDeckKey csv_keys[] = {
    {.path = "displacements_csv", .type = MICA_KEY_BOOL, .def = "false", .min = 1.0, .max = 0.0,
     .help = "test extension: write displacements.csv, the particles' displacements after the solve"},
    {0},
};

static int csv_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options) {
  (void)type;
  return mica_settings_bool(settings, group, "displacements_csv", &((MicaOutput *)options)->enabled);
}

static void write_rows(FILE *fp, const MicaOutputFields *f, const MicaVtkField *disp) {
  static const char *const axes[3] = {"x", "y", "z"};
  for (int d = 0; d < f->dim; d++) fprintf(fp, "%s,", axes[d]);
  fprintf(fp, "ux,uy,uz\n");
  for (long i = 0; i < f->npoints; i++) {
    for (int d = 0; d < f->dim; d++) fprintf(fp, "%.17g,", f->x[i * f->dim + d]);
    const double *u = disp->data + i * 3;
    fprintf(fp, "%.17g,%.17g,%.17g\n", u[0], u[1], u[2]);
  }
}

static int csv_finish(MicaOutputRun *run, void *ctx, const double *u, MicaJson *summary) {
  (void)ctx, (void)summary;
  MicaOutputFields f;
  MicaOutFile out = {0};
  int ierr = MICA_SUCCESS;
  MICA_CALL(mica_output_particle_fields(run, u, &f));
  const MicaVtkField *disp = mica_output_field(&f, "displacement");
  if (!disp) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_ARGUMENT, "displacements_csv: no displacement");
    goto cleanup;
  }
  MICA_CALL_CLEANUP(mica_out_open_in(mica_output_dir(run), "displacements.csv", &out));
  write_rows(out.fp, &f, disp);
  MICA_CALL_CLEANUP(mica_out_commit(&out));
cleanup:
  mica_out_abort(&out);
  mica_output_fields_free(&f);
  return ierr;
}

static const MicaOutputOps displacements_csv = {
    .type = {"displacements_csv", "test extension: the particles' displacements after the solve (CSV)",
             MICA_OUTPUT_AT_END | MICA_OUTPUT_RANK0, csv_keys, csv_from_settings},
    .finish = csv_finish,
};

__attribute__((constructor)) static void register_displacements_csv(void) {
  if (mica_registry_add(&mica_output_registry, &displacements_csv.type)) {
    mica_error_report("tests/extensions/output_displacements_csv.c");
    exit(1);
  }
}
