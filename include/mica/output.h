/* Outputs of `mica run`: a registry of types (mica/registry.h, docs/architecture.md §outputs). Each output is
 * one file that fills a MicaOutputOps: its name, a one-line description, its capability flags, its own deck
 * settings (under output.*, with defaults and help: the run schema takes them from the registry, so they are
 * declared once, by the type) and its ops. The run reads every registered type's settings (from_settings says
 * whether the deck enables it), then calls the enabled ones at the points the flags name: after each converged
 * load step (step), after the solve (finish). Adding an output is its file and one mica_registry_add (a
 * constructor, as tests/extensions/output_displacements_csv.c does). summary.json is not an output: it is the
 * run's record, which every command writes and to which outputs add members. */
#ifndef MICA_OUTPUT_H
#define MICA_OUTPUT_H

#include <stddef.h>

#include "mica/json.h"
#include "mica/registry.h"
#include "mica/vtk.h"

/* Capability flags (MicaType.flags) of an output type; the run asks them (mica_type_has). */
enum {
  MICA_OUTPUT_PER_STEP = 1u << 0, /* step() after every converged load step */
  MICA_OUTPUT_AT_END = 1u << 1,   /* finish() after the solve reached the full load */
  MICA_OUTPUT_REACHED = 1u << 2,  /* finish() also after a solve that failed: it reports the converged steps */
  MICA_OUTPUT_CELLS = 1u << 3,    /* needs the cells of the output mesh (the discretization's disc->mesh) */
  MICA_OUTPUT_RANK0 = 1u << 4,    /* under MPI rank 0 alone calls it (the solution is whole on every rank);
                                     without the flag every rank does, as a collective (sums over the ranks) */
  MICA_OUTPUT_PVD_PART = 1u << 5, /* its file of each step is a part of solution.pvd (`part`, `pattern`) */
  MICA_OUTPUT_PIECES = 1u << 6    /* under MPI every rank writes its piece of each step (its particles, its
                                     cells) and rank 0 the .pvtu that lists them (`pieces_pattern`), which
                                     solution.pvd names instead; a serial run writes `pattern` */
};

/* The run being written: opaque to a type, read through the functions below (src/app/run_output.c). */
typedef struct MicaOutputRun MicaOutputRun;

typedef struct MicaOutputOps {
  /* keys: paths under "output" ("vtu" is output.vtu); from_settings(type, settings, "output", MicaOutput *)
   * sets enabled and reads the type's settings into its context; NULL from_settings: always enabled */
  MicaType type;
  size_t size;         /* bytes of the type's context (its settings and state), zeroed; 0: none */
  const char *part;    /* MICA_OUTPUT_PVD_PART: the part's name in solution.pvd ("particles") */
  const char *pattern; /* and its file of load step k, a printf format of k ("step_%04d.vtu") */
  const char *pieces_pattern; /* MICA_OUTPUT_PIECES under MPI: the .pvtu of step k ("step_%04d.pvtu") */
  /* After the problem is built, before the solve (and in `mica check`): the settings against the problem,
   * MICA_ERR_INPUT with the deck line. NULL: nothing to check. */
  int (*check)(MicaOutputRun *run, void *ctx);
  int (*step)(MicaOutputRun *run, void *ctx, int step, double t, const double *u);
  /* u: the final solution (NULL after a failed solve: only REACHED types are called then) */
  int (*finish)(MicaOutputRun *run, void *ctx, const double *u, MicaJson *summary);
  void (*destroy)(void *ctx); /* frees what the context holds (not the context); NULL: nothing */
} MicaOutputOps;

/* One registered output in a run: what from_settings fills. */
typedef struct MicaOutput {
  const MicaOutputOps *ops;
  int enabled; /* the deck asks for it */
  void *ctx;   /* ops->size bytes, zeroed (NULL when 0) */
} MicaOutput;

extern MicaRegistry mica_output_registry;

static inline const MicaOutputOps *mica_output_ops_of(const MicaType *type) { return (const MicaOutputOps *)type; }

/* The run's output directory (the staging directory the command line publishes). */
const char *mica_output_dir(const MicaOutputRun *run);
/* Whether this process writes the files of a RANK0 output (rank 0, or a serial run). */
int mica_output_writer(const MicaOutputRun *run);

/* The fields of the solution u at points, as the VTU files hold them (displacement, microrotation, strain,
 * stress, couple_stress, micro_deformation, von_mises, error: those the model has), in the file frame (an
 * axisymmetric section's components r, z, theta). */
typedef struct MicaOutputFields {
  int dim;                 /* of the points */
  long npoints;
  const double *x;         /* [npoints * dim] */
  int nfields;
  MicaVtkField fields[9];
  double *storage[9];      /* owned: the fields' values, and a copy of the points' coordinates if x is one */
} MicaOutputFields;
/* At the particles, or at the points of the output mesh (MICA_OUTPUT_CELLS types only). */
int mica_output_particle_fields(MicaOutputRun *run, const double *u, MicaOutputFields *fields);
int mica_output_mesh_fields(MicaOutputRun *run, const double *u, MicaOutputFields *fields);
/* The field of that name ("displacement"), or NULL. */
const MicaVtkField *mica_output_field(const MicaOutputFields *fields, const char *name);
void mica_output_fields_free(MicaOutputFields *fields);

#endif
