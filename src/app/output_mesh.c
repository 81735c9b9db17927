/* output.mesh: with output.vtu, the same fields on the cells after every converged load step, mesh_NNNN.vtu,
 * part "mesh" of solution.pvd. Each vertex value is what a probe there reports: the shape functions at the mesh's
 * points come through the approximation's points op, as a probe's do (run_output.c). Under MPI each rank writes
 * a piece, mesh_NNNN_R.vtu — with replicated data its range of the whole mesh (run_mesh_piece_range: cells
 * [c P / n ... ) of n, by index), with distributed data the mesh of its own cells — and rank 0 mesh_NNNN.pvtu; a
 * serial run writes mesh_NNNN.vtu as before. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"
#include "run.h"

MICA_SCHEMA_TABLES

static const MicaDeckKey mesh_keys[] = {
    {"mesh", MICA_KEY_BOOL, "true", 1.0, 0.0, NULL, 0, 0,
     "with output.vtu: also the fields on the cells (mesh_NNNN.vtu, part 1 of solution.pvd)"},
    {NULL},
};

/* Enabled with output.vtu only. A deck that asks for mesh files (output.mesh = true) with output.vtu = false would
 * get none and is refused; output.mesh = false agrees with it, and so does the default (sweep and study points
 * turn output.vtu off by themselves, and a deck that leaves the mesh on must still run there). */
static int mesh_from_settings(const MicaType *type, const MicaSettings *settings, const char *group, void *options) {
  (void)type;
  int mesh, vtu;
  MICA_CALL(mica_settings_bool(settings, group, "mesh", &mesh));
  MICA_CALL(mica_settings_bool(settings, group, "vtu", &vtu));
  char where[256];
  mica_settings_where(settings, group, "mesh", where, sizeof where);
  const int given = !strstr(where, " (default)"); /* in the deck or a --set, not the schema's default */
  MICA_CHECK(vtu || !mesh || !given, MICA_ERR_INPUT,
             "%s: output.mesh = true writes the fields on the cells with the VTU files, but output.vtu = false writes "
             "none; remove output.mesh or set output.vtu = true", where);
  ((MicaOutput *)options)->enabled = mesh && vtu;
  return MICA_SUCCESS;
}

static const char *const piece_pattern = "mesh_%04d_%d.vtu";

static int mesh_step_serial(MicaOutputRun *run, int step, const double *u) {
  const MicaCellMesh *mesh = run->rp->disc->mesh;
  MicaOutputFields f;
  char name[32], *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(mica_output_mesh_fields(run, u, &f));
  snprintf(name, sizeof name, run_output_mesh.pattern, step);
  MICA_CALL_CLEANUP(mica_path_join(mica_output_dir(run), name, &path));
  const MicaVtkCells cells = {mesh->ncells, mesh->offsets, mesh->conn, mesh->type};
  MICA_CALL_CLEANUP(mica_vtu_write_cells(path, f.dim, f.npoints, f.x, &cells, f.nfields, f.fields));
cleanup:
  free(path);
  mica_output_fields_free(&f);
  return ierr;
}

/* MPI: this rank's cells (none when there are fewer cells than ranks: then no piece), and rank 0's .pvtu. */
static int mesh_step_piece(MicaOutputRun *run, int step, const double *u) {
  const long ncells = run->rp->disc->mesh->ncells;
  MicaOutputFields f;
  RunMeshPiece piece;
  char name[64], *path = NULL;
  int ierr = MICA_SUCCESS;
  MICA_CALL(run_output_mesh_piece(run, u, &f, &piece));
  if (piece.ncells > 0) {
    snprintf(name, sizeof name, piece_pattern, step, mica_parallel_rank());
    MICA_CALL_CLEANUP(mica_path_join(run->piece_dir, name, &path));
    MICA_CALL_CLEANUP(mica_vtu_write_cells(path, f.dim, f.npoints, f.x, &piece.cells, f.nfields, f.fields));
  }
  if (mica_parallel_rank() == 0) {
    snprintf(name, sizeof name, run_output_mesh.pieces_pattern, step);
    /* distributed data: every rank has cells and writes a piece (ncells 0: all of them) */
    MICA_CALL_CLEANUP(run_output_pvtu(run, name, piece_pattern, step, run->rp->owned_data ? 0 : ncells, &f));
  }
cleanup:
  free(path);
  run_mesh_piece_free(&piece);
  mica_output_fields_free(&f);
  return ierr;
}

static int mesh_step(MicaOutputRun *run, void *ctx, int step, double t, const double *u) {
  (void)ctx, (void)t;
  return run->rp->dist ? mesh_step_piece(run, step, u) : mesh_step_serial(run, step, u);
}

const MicaOutputOps run_output_mesh = {
    .type = {"mesh", "the fields on the cells of the output mesh per load step (mesh_NNNN.vtu; MPI: a piece per rank)",
             MICA_OUTPUT_PER_STEP | MICA_OUTPUT_CELLS | MICA_OUTPUT_PVD_PART | MICA_OUTPUT_PIECES, mesh_keys,
             mesh_from_settings},
    .part = "mesh",
    .pattern = "mesh_%04d.vtu",
    .pieces_pattern = "mesh_%04d.pvtu",
    .step = mesh_step,
};
