/* Internal interface of `mica run` and `mica check` (src/app/run*.c). */
#ifndef MICA_RUN_H
#define MICA_RUN_H

#include "mica/command.h"
#include "mica/fe.h"
#include "mica/output.h"
#include "mica/parallel.h"
#include "mica/bc.h"

extern const MicaDeckKey mica_run_schema[];

/* What consecutive runs (a sweep's points) keep between them: the discretization and MLS approximation of
 * the last run while the settings they depend on do not change, and its solid, whose shape-function caches
 * the next solid shares when its model needs the same derivatives (run.c: geometry_scopes). */
typedef struct RunReuse RunReuse;
int run_reuse_create(RunReuse **reuse);
int run_reuse_destroy(RunReuse **reuse);

/* The cost of a run from its deck (estimate.c, docs/performance.md §the cost estimate): counts, the peak
 * memory of the parts (bytes) and a rough time, all in double so that no count wraps. */
typedef struct RunEstimate {
  int valid;                   /* 0: not estimated */
  double particles, points, boundary_points, support, dofs, nnz, factor_entries;
  double cache_bytes, matrix_bytes, factor_bytes, bytes; /* bytes: the peak of a run, with a safety factor */
  double seconds;              /* rough: shape functions, one assembly and one factorization */
  const char *solver;          /* "cholmod", "cholmod-sym" or "umfpack" (what solver.linear = "auto" takes in one process), "petsc"
                                  (a direct method: MUMPS's factor estimated like CHOLMOD's) or "petsc-iterative" */
  int petsc_copy;              /* solver.linear = "petsc": PETSc's copy of the matrix */
} RunEstimate;
/* A Gmsh mesh's counts for the estimate: of its discretization once built (run_mesh_counts), or of its reader's
 * first pass under parallel.data = "distributed" (nodes for particles, volume elements for cells). */
typedef struct {
  int dim;
  double particles, cells, points, boundary_points;
} RunMeshCounts;
void run_mesh_counts(const MicaDiscretization *disc, RunMeshCounts *c);
/* From a built-in shape's counts (mesh NULL) or a Gmsh mesh's. */
int run_estimate(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                 const MicaCellSpec *cells, const RunMeshCounts *mesh, RunEstimate *est);
/* MICA_ERR_INPUT with the deck line of particles.count (or geometry.mesh; layout NULL), the estimate and the
 * setting to change when est->bytes exceeds limits.memory_gb (default: the physical memory). */
int run_estimate_guard(const MicaDeck *deck, const MicaLayoutSpec *layout, int dim, const RunEstimate *est);
/* Prints the estimate and puts estimate_memory, estimate_seconds, estimate_factor_entries in the summary. */
int run_estimate_report(const RunEstimate *est, MicaJson *summary);
double run_physical_memory(void); /* bytes (sysconf), 0 if unknown */
/* A mesh file must be a regular file of at most limits.mesh_mb, checked before it is opened. */
int run_mesh_file_check(const MicaDeck *deck, const char *path);

/* quadrature.vci (run_vci.c): "auto" (the default) decides by the layout and by what the run combines it
 * with, in one place; true and false are taken as given. */
typedef struct RunVciFacts {
  int fe, model_order, axisymmetric, symmetric_only; /* model_order 0: not known yet (1 assumed) */
  int parallel; /* under MPI with replicated data (distributed data has VCI) */
  long boundary_uncovered;
} RunVciFacts;
typedef struct RunVciChoice {
  int on;           /* VCI applies */
  int automatic;    /* quadrature.vci = "auto" */
  int nodal;        /* auto turned it on for a nodal mode (nsni), not for the layout */
  char reason[128]; /* auto: why on or off */
} RunVciChoice;
int run_vci_choose(const MicaDeck *deck, const RunVciFacts *facts, RunVciChoice *c);
/* Whether this is an MPI run with parallel.data = "replicated" (RunVciFacts.parallel). */
int run_vci_replicated_parallel(const MicaDeck *deck, int *replicated);
/* auto: one line at the start of the run, what it chose, why and what it costs. */
int run_vci_report(const RunVciChoice *c, const MicaSolidOptions *opt);
/* vci_setting ("auto", "true", "false") and, for auto, vci_reason. */
int run_vci_summary(const RunVciChoice *c, MicaJson *summary);

/* Everything a run builds from its deck, and the times of the phases that built it. */
typedef struct RunProblem {
  const MicaDeck *deck;
  MicaDiscretization *disc;
  MlsApprox *mls;               /* problem.method = "efg" */
  MicaFe *fe;                   /* problem.method = "fe" */
  MicaApprox approx;            /* the one of the two the solid uses */
  MicaSolid *solid;
  MicaFunction *exact[MICA_MAX_COMP];      /* exact unknowns (displacements, micro-rotations), or NULL */
  MicaFunction *exact_grad[MICA_MAX_COMP][3]; /* their gradients ∂v_c/∂X_J */
  int has_exact, ncomp;
  int axisymmetric;             /* geometry.axisymmetric: a 2-D (r, z) section, 3-D model, cylindrical components */
  MicaShapeCache *at_particles; /* shape functions at the particles, for output (built on first use) */
  MicaShapeCache *at_mesh;      /* and at the points of the output mesh (disc->mesh) */
  MicaDistribution *dist;       /* MPI: the partition and this rank's points (NULL: serial) */
  MicaMeshSource *mesh_source;  /* parallel.data = "distributed" with a Gmsh mesh: its reader (groups, sample),
                                   from the geometry until the distribution has read its part (run_parallel_distribute) */
  char *mesh_file;              /* a .geo under MPI: the .msh rank 0 had Gmsh write for every rank to read, until
                                   the distribution has read it (run_mesh_file_remove) */
  const char *integration;      /* quadrature.mode: "gauss", "nodal" or "scni" */
  MicaShapeCache *at_gauss;     /* nodal and scni: MLS shape functions at the background Gauss points, where the
                                   error norms are measured (NULL in gauss mode: the volume cache is there);
                                   with quadrature.error_order, at error_disc's points */
  MicaDiscretization *error_disc; /* quadrature.error_order > 0: the error norms' own Gauss points (built on
                                   first use, run_error_discretization), else NULL */
  double time_discretize, time_mls, time_cache_pattern; /* time_mls: the MLS or finite-element setup */
  double cpu_cache_pattern;     /* thread CPU time of the cache and pattern (mica_cputime) */
  RunReuse *reuse;              /* NULL: a single run */
  long peak_build;              /* peak resident memory once the discretization, MLS and distribution are built, before
                                   the solid's caches (getrusage: this rank's) */
  int owns_geometry;            /* 1: disc and mls are this run's to free (else reuse keeps them) */
  int reused_geometry;          /* 1: disc and mls came from the previous run */
  RunEstimate estimate;         /* the cost guard's estimate (estimate.c), made before the discretization */
  double *near_null;            /* solver.linear = "petsc": the rigid motions, [count][ndof] (run_linear.c) */
  int owned_data;               /* parallel.data = "distributed" under MPI: disc and approx are this rank's block
                                   and ghosts (dist->local, dist->mls); the whole ones were freed */
  RunVciChoice vci;             /* quadrature.vci as resolved (run_vci.c) */
  int symmetric_only;           /* the analysis needs the symmetric Galerkin tangent (mica stability): auto VCI off */
} RunProblem;

/* The dimension of the model's kinematics (3 for an axisymmetric section) and the deck's name of unknown c
 * ("ux", "phiz"; axisymmetric "ur", "utheta", ...). */
int run_model_dim(const RunProblem *rp);
const char *run_unknown_name(const RunProblem *rp, int c);

/* ---- run_conditions.c: the conditions of the deck, read for the problem's model ---- */
/* The unknowns' (traction = 0) or the tractions' names of model m in rp's geometry, NULL-ended; returns their
 * number. */
int run_model_names(const RunProblem *rp, const MicaFieldModel *m, int traction, const char **names);
int run_read_dirichlet(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, int *count,
                       MicaDirichlet **out);
int run_read_tractions(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, int *count,
                       MicaTraction **out);
int run_read_body_force(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *m, MicaFunction **body);
/* bc.method and the method's own settings (bc.alpha) into opt. */
int run_read_bc_method(const MicaDeck *deck, MicaSolidOptions *opt);
/* The exact.* solution, when the deck gives one, into rp. */
int run_read_exact(const MicaDeck *deck, RunProblem *rp, const MicaFieldModel *m);

/* The model and its constants from material.* (run_material.c). */
int run_read_material(const MicaDeck *deck, int dim, MicaSolidOptions *opt);
/* material.pressure into opt->pressure, checked against the model, plane kind, integration and MPI (after
 * run_read_scni: rp->integration). */
int run_read_pressure(const MicaDeck *deck, const RunProblem *rp, MicaSolidOptions *opt);

/* The approximation and integration choices (run_method.c). problem.method: run_is_fe; for "fe", the deck
 * checks (grid, order, odd counts, cells = elements; *order from mls.order), the mesh and discretization
 * that replace the shape's, and the model / multiplier restrictions. quadrature.mode: nodal cells for
 * "nodal" and "scni" (run_read_integration, with the discretization), opt->scni and its restrictions
 * (run_read_scni). run_check_serial_only refuses the FE measuring stick under MPI, and the nodal modes under MPI
 * with replicated data (distributed data builds each rank's nodal cells). All with the deck line. */
int run_is_fe(const MicaDeck *deck, int *fe);
/* quadrature.mode: a registry of types (gauss, the default; nodal; scni; nsni), flags RUN_INTEGRATION_*. */
enum {
  RUN_INTEGRATION_NODAL = 1u << 0,   /* at the particles, weighted by their nodal cells (needs a logical grid) */
  RUN_INTEGRATION_SMOOTHED = 1u << 1,  /* smoothed (SCNI) gradients on the nodal cells: first derivatives only */
  RUN_INTEGRATION_STABILIZED = 1u << 2 /* NSNI's gradient terms from the MLS Hessians (docs/theory.md §NSNI) */
};
extern MicaRegistry run_integration_registry;
/* The flags of the deck's quadrature.mode. */
int run_integration_flags(const MicaDeck *deck, unsigned *flags);
int run_check_fe_deck(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                      const MicaCellSpec *cells, int *order);
int run_build_fe(const MicaLayoutSpec *layout, const MicaCellSpec *cells, int order, RunProblem *rp);
int run_check_fe_model(const MicaDeck *deck, const RunProblem *rp, const MicaSolidOptions *opt);
int run_check_fe_multipliers(const MicaDeck *deck, const RunProblem *rp, const MicaSolidOptions *opt, int n,
                             const MicaDirichlet *c);
/* build = 0: the checks only (parallel.data = "distributed" under MPI: each rank builds its own cells, own.c). */
int run_read_integration(const MicaDeck *deck, const MicaShapeSpec *shape, const MicaLayoutSpec *layout,
                         const MicaCellSpec *cells, int build, RunProblem *rp);
int run_read_scni(const MicaDeck *deck, RunProblem *rp, MicaSolidOptions *opt);

int run_check_serial_only(const MicaDeck *deck, const RunProblem *rp, int distributed);

/* The deck's geometry (run_geometry.c): the shape (mesh: a buffer for a Gmsh mesh's path, beside the deck), the
 * particle layout and the background cells (gmsh: the counts come from the mesh), checked with the deck line. */
int run_read_shape(const MicaDeck *deck, MicaShapeSpec *shape, char *mesh, size_t mesh_size);
int run_read_layout(const MicaDeck *deck, int dim, int gmsh, MicaLayoutSpec *layout, MicaCellSpec *cells);
/* The cost guard (estimate.c) for a built-in shape, from its counts, before anything is allocated (a Gmsh
 * mesh's is run_build_geometry's, once the mesh is read). */
int run_guard_cost(const MicaDeck *deck, RunEstimate *est);
/* The discretization (revolved for an axisymmetric section), with the finite elements or the MLS
 * approximation of problem.method, into rp. */
/* Rank 0 removes the .msh written for a .geo under MPI (rp->mesh_file), once every rank has read its part. */
void run_mesh_file_remove(RunProblem *rp);
int run_build_geometry(const MicaDeck *deck, RunProblem *rp);

/* Builds discretization, MLS, model, conditions and the solid from the deck; with reuse, takes what the
 * previous run left there when it fits, and leaves this run's parts there in run_problem_free. */
int run_problem_build(const MicaDeck *deck, RunProblem *rp);
/* The same for an analysis of the symmetric Galerkin tangent (mica stability): quadrature.vci = "auto" is off. */
int run_problem_build_symmetric(const MicaDeck *deck, RunProblem *rp);
/* quadrature.error_order > 0: the deck's body, particles and cells with that many Gauss points per direction
 * (revolved if axisymmetric), whose volume points the error norms use; NULL when the key is 0. */
int run_error_discretization(const RunProblem *rp, MicaDiscretization **disc);
/* The deck's body (the shape of geometry.*, or its Gmsh mesh), for asking whether a point lies in it. */
int run_body_create(const MicaDeck *deck, MicaBody **body);
int run_problem_build_reusing(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse);
void run_problem_free(RunProblem *rp);

/* `mica run` on a checked deck, reusing what the previous run left in reuse (NULL: nothing). */
int run_solve_reusing(const MicaDeck *deck, const char *outdir, MicaJson *summary, RunReuse *reuse);
/* MPI (run_parallel.c): the distribution from parallel.data (METIS's partition of the replicated particles, or each
 * rank's block); its partition and per-rank counts in the summary and the log (nothing in a serial run). */
typedef struct RunTotals {
  long nnz;                 /* of the (whole) tangent */
  long support_entries, support_points, max_support; /* volume points' supports */
  long cache_bytes;         /* shape-function caches, all ranks together */
  /* the whole problem's counts: rp->disc's and the solid's, or with distributed data the sums over the ranks'
   * owned particles, cells and points */
  long particles, cells, quadrature_points, boundary_points, dofs;
  double volume;
} RunTotals;
int run_parallel_distribute(const MicaDeck *deck, RunProblem *rp);
/* The rigid motions the conditions leave free: a deck error (run_counts.c; on rp->disc). */
int run_check_rigid(const MicaDeck *deck, const RunProblem *rp, const MicaFieldModel *field, int ndirichlet,
                    const MicaDirichlet *dirichlet);
/* parallel.data = "distributed": refuses (deck error, the setting named) what it does not cover yet. */
int run_parallel_owned_check(const MicaDeck *deck, const RunProblem *rp);

int run_parallel_totals(const RunProblem *rp, RunTotals *totals);
int run_parallel_counts(const RunProblem *rp, MicaJson *summary);
/* summary.json: peak_memory_build (this rank's peak once the geometry was built) and under MPI its largest over the
 * ranks, peak_memory_build_max (collective). */
int run_build_memory(const RunProblem *rp, MicaJson *summary);
int run_parallel_memory(const RunProblem *rp, MicaJson *summary);
/* Collective: each rank's points, matrix entries and the wall and CPU time of its distributed work (cache and
 * pattern, assemblies, and the assemblies' wait for the residual sum), printed per rank and in the summary
 * ("cpu_assemble", "cpu_cache_and_pattern" of this process also in a serial run). */
int run_parallel_ranks(const RunProblem *rp, const MicaNewtonStats *stats, MicaJson *summary);

/* What run and check share (run_counts.c): the problem built (with reuse, NULL: none), its rigid modes and
 * outputs read and checked (run_outputs_read: every output type's settings), its sizes counted into totals, printed and in the
 * summary with the cost estimate. rp is the caller's to free (run_problem_free), also on failure. */
struct MicaOutputRun;
int run_problem_prepare(const MicaDeck *deck, RunProblem *rp, RunReuse *reuse, const char *outdir, struct MicaOutputRun *out,
                        RunTotals *totals, MicaJson *summary);

/* The iterative linear solvers' settings (run_linear.c): solver.linear_rtol, .linear_max_iterations and the chosen
 * solver's own (petsc: solver.petsc, .petsc_options) into opt->krylov; their iterations (and under MPI the halo)
 * in the summary; the process's peak memory ("peak_memory", bytes). */
int run_read_krylov(const MicaDeck *deck, RunProblem *rp, MicaNewtonOptions *opt);
int run_krylov_summary(const RunProblem *rp, const MicaNewtonStats *st, MicaJson *summary);
int run_peak_memory(MicaJson *summary);

/* Output (run_output.c): the registry of output types (mica/output.h; output_*.c, one type each) and the run
 * that drives them. run_outputs_read reads every registered type's settings and checks the enabled ones against
 * the built problem (after the build, in `mica run` and `mica check`); run_output_step is Newton's callback after
 * each converged load step; run_outputs_finish calls the enabled types' finish (failed: a solve that stopped,
 * only the MICA_OUTPUT_REACHED types, u NULL). */
struct MicaOutputRun {
  RunProblem *rp;
  const char *outdir;
  int noutputs;
  MicaOutput *outputs;  /* every registered type, in registry order; enabled or not */
  char *piece_dir;      /* MPI (rp->dist): rank 0's outdir, where every rank writes its pieces; NULL serial */
  int nsteps, capacity; /* steps written to the PVD's parts; grown as needed (cut-backs add steps) */
  int *steps;           /* the load step of each, naming step_NNNN.vtu and mesh_NNNN.vtu */
  double *times;        /* its load factor */
  double time_output;   /* seconds writing fields per step, error norms and probes (profiles) */
};
typedef struct MicaOutputRun RunOutput;

/* The built-in output types, one file each (output_vtu.c, output_mesh.c, output_monitor.c, output_pvd.c,
 * output_probes.c, output_quadrature_fields.c). */
extern const MicaOutputOps run_output_vtu, run_output_mesh, run_output_monitor, run_output_pvd, run_output_probes,
    run_output_quadrature_fields;
int run_outputs_read(RunProblem *rp, const char *outdir, RunOutput *out);
int run_output_step(void *ctx, int step, double t, const double *u);
int run_outputs_finish(RunOutput *out, int failed, const double *u, MicaJson *summary);
void run_output_free(RunOutput *out);
/* MPI (rp->dist): this rank's piece of the VTU outputs, the fields at its own particles (partition->part), and
 * at the points of its cells of the output mesh: cells [first, end) of run_mesh_piece_range, contiguous blocks
 * of ncells / P (the last takes the rest), and the points they use, renumbered in ascending order (a point that
 * cells of two pieces share is in both). */
typedef struct RunMeshPiece {
  long ncells, npoints;
  long *offsets, *conn; /* renumbered to the piece's points */
  unsigned char *type;
  long *points;         /* [npoints] the mesh's index of each */
  MicaVtkCells cells;
} RunMeshPiece;
int run_output_particle_piece(RunOutput *out, const double *u, MicaOutputFields *fields);
int run_output_mesh_piece(RunOutput *out, const double *u, MicaOutputFields *fields, RunMeshPiece *piece);
void run_mesh_piece_range(long ncells, int piece, int npieces, long *first, long *end);
void run_mesh_piece_free(RunMeshPiece *piece);
/* Under MPI the .pvtu of a step: rank 0 lists the pieces pattern % (step, piece) of the pieces that exist (all
 * npieces, or those with cells: cells = the mesh's count, 0 for particles). */
int run_output_pvtu(RunOutput *out, const char *name, const char *piece_pattern, int step, long ncells,
                    const MicaOutputFields *fields);

/* Shared by the outputs (run_output.c): the von Mises equivalent of a 3×3 Cauchy stress, and the force stress,
 * couple stress and (classical models) strain, 3×3 each, at the model's kinematics q. */
double run_von_mises(const double *s);
int run_stresses(const RunProblem *rp, const double *q, double *sigma, double *couple, double *strain);
int run_error_norms(RunProblem *rp, const double *u, MicaJson *summary);
/* The relative errors run_error_norms reports (L2 of the values, H1 seminorm, energy), without writing them. */
int run_error_values(RunProblem *rp, const double *u, double *rel_l2, double *rel_h1, double *rel_energy);
/* The points the error norms use, their shape functions and weights: quadrature.error_order's own points
 * (whole = 1: every rank holds all of them), else the solve's volume points (under nodal integration the
 * background Gauss points; under MPI this rank's). */
int run_error_points(RunProblem *rp, const MicaShapeCache **c, const double **x, const double **w, int *whole);
#endif
