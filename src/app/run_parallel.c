/* `mica run` and `mica check` under MPI (src/parallel): the deck's parallel settings, and the partition's and the
 * ranks' numbers in the summary and the log. Nothing here runs in a serial run. */
#include <limits.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "run.h"
#include "study_common.h"

/* parallel.data = "distributed": what it does not cover yet is refused, naming the setting (no silent replication). */
static int refuse_owned(const MicaDeck *deck, const char *path, const char *what) {
  char where[256];
  mica_deck_where(deck, mica_deck_given(deck, path) ? path : "parallel.data", where, sizeof where);
  MICA_ERROR(MICA_ERR_INPUT, "%s: %s is not available with parallel.data = \"distributed\" yet; %s, or use "
             "parallel.data = \"replicated\"", where, path, what);
}

int run_parallel_owned_check(const MicaDeck *deck, const RunProblem *rp) {
  const char *linear;
  MICA_CALL(mica_deck_string(deck, "solver.linear", &linear));
  const MicaLinearSolverOps *ops = mica_linear_solver_find(linear); /* NULL: "auto", petsc under MPI */
  if (ops && !mica_linear_solver_has(ops, MICA_LINEAR_DISTRIBUTED))
    return refuse_owned(deck, "solver.linear", "set solver.linear = \"petsc\" or \"auto\" (the distributed matrix)");
  /* (a Gmsh mesh and the irregular layout take NSNI, their cells from the Gauss points, as serially; the other nodal
   * modes need the particle grid's dual cells and are refused serially) */
  if (rp->fe) return refuse_owned(deck, "problem.method", "use problem.method = \"efg\"");
  return MICA_SUCCESS;
}

int run_parallel_distribute(const MicaDeck *deck, RunProblem *rp) {
  if (rp->owned_data) {
    MlsOptions mls_opt;
    MicaShapeSpec shape;
    MicaLayoutSpec layout;
    MicaCellSpec cells;
    char mesh[PATH_MAX];
    MICA_CALL(run_read_shape(deck, &shape, mesh, sizeof mesh));
    MICA_CALL(run_read_layout(deck, shape.dim, shape.kind == MICA_SHAPE_GMSH, &layout, &cells));
    long error_order;
    unsigned flags;
    int output_mesh, output_vtu;
    MICA_CALL(mica_deck_bool(deck, "output.mesh", &output_mesh));
    MICA_CALL(mica_deck_bool(deck, "output.vtu", &output_vtu));
    MICA_CALL(mica_study_mls_options(deck, rp->disc->dim, &mls_opt));
    MICA_CALL(mica_deck_int(deck, "quadrature.error_order", &error_order));
    MICA_CALL(run_integration_flags(deck, &flags));
    const MicaOwnedSpec spec = {
        .error_order = (int)error_order,
        .nodal = (flags & RUN_INTEGRATION_NODAL) != 0,
        .centroids = (flags & RUN_INTEGRATION_STABILIZED) != 0,
        .cell_boundaries = (flags & RUN_INTEGRATION_SMOOTHED) != 0,
        .wider_support = (flags & RUN_INTEGRATION_STABILIZED) ? mica_nsni_hessian_reach(mls_opt.order) : 0,
        .revolve = rp->axisymmetric,
        .mesh = output_mesh && output_vtu, /* output_mesh.c: enabled with the VTU files */
    };
    if (shape.kind == MICA_SHAPE_GMSH) {
      MICA_CHECK(rp->mesh_source, MICA_ERR_ARGUMENT, "run_parallel_distribute: the Gmsh mesh's reader was not kept");
      const int ierr = mica_distribution_create_owned_mesh(rp->mesh_source, &cells, &mls_opt, &spec, &rp->dist);
      mica_mesh_source_close(&rp->mesh_source); /* each rank keeps its part (dist->cells_mesh) */
      MICA_CALL(mica_parallel_agree(ierr));     /* every rank has read the file: a .geo's may go */
      run_mesh_file_remove(rp);
    } else {
      MICA_CALL(mica_distribution_create_owned(&shape, &layout, &cells, &mls_opt, &spec, &rp->dist));
    }
    const MicaDistribution *d = rp->dist;
    printf("MPI: %d ranks, parallel.data = distributed: blocks %d × %d × %d of the %s, particles per rank "
           "%ld (+ up to %ld ghosts), quadrature points per rank %ld to %ld (%.3g s)\n",
           mica_parallel_size(), d->procs[0], d->procs[1], d->procs[2],
           shape.kind == MICA_SHAPE_GMSH ? "mesh's particles (coordinate cuts)" : "index grids", d->nowned,
           d->stats.ghost_particles_max, d->stats.min_owned_points, d->stats.max_owned_points, d->stats.time_partition);
    fflush(stdout);
    return MICA_SUCCESS;
  }
  MICA_CALL(mica_distribution_create(rp->disc, rp->mls, &rp->dist));
  const MicaDistribution *d = rp->dist;
  printf("MPI: %d ranks, METIS edge cut %ld, imbalance %.3f; quadrature points per rank %ld to %ld, ghost particles "
         "up to %ld (partition %.3g s)\n",
         mica_parallel_size(), d->partition->edge_cut, d->partition->imbalance, d->stats.min_owned_points,
         d->stats.max_owned_points, d->stats.ghost_particles_max, d->stats.time_partition);
  fflush(stdout);
  return MICA_SUCCESS;
}

/* parallel.data = "distributed": the whole problem's counts are the sums of the ranks' owned parts. */
static int owned_totals(const RunProblem *rp, RunTotals *c) {
  const MicaDistribution *d = rp->dist;
  MICA_CALL(mica_owned_matrix_nnz(d, rp->solid->K, &c->nnz));
  c->particles = d->nparticles;
  c->dofs = d->nglobal_nodes * rp->solid->ncomp; /* with the multiplier nodes, as serially */
  c->cells = mica_parallel_sum_long(c->cells);
  c->quadrature_points = mica_parallel_sum_long(c->quadrature_points);
  c->boundary_points = mica_parallel_sum_long(c->boundary_points);
  return MICA_SUCCESS; /* the volume: the body's, summed when the distribution was built */
}

int run_parallel_totals(const RunProblem *rp, RunTotals *c) {
  if (rp->owned_data) MICA_CALL(owned_totals(rp, c));
  else MICA_CALL(mica_parallel_matrix_nnz(rp->solid->K, &c->nnz));
  c->support_entries = mica_parallel_sum_long(c->support_entries);
  c->support_points = mica_parallel_sum_long(c->support_points);
  c->max_support = mica_parallel_max_long(c->max_support);
  c->cache_bytes = mica_parallel_sum_long(c->cache_bytes);
  return MICA_SUCCESS;
}

int run_parallel_counts(const RunProblem *rp, MicaJson *summary) {
  const MicaDistribution *d = rp->dist;
  if (!d) return MICA_SUCCESS;
  MICA_CALL(mica_json_string(summary, "parallel_data", d->owned ? "distributed" : "replicated"));
  if (d->owned) {
    MICA_CALL(mica_json_open_array(summary, "parallel_blocks"));
    for (int k = 0; k < 3; k++) MICA_CALL(mica_json_int(summary, NULL, d->procs[k]));
    MICA_CALL(mica_json_close(summary));
  } else {
    MICA_CALL(mica_json_int(summary, "edge_cut", d->partition->edge_cut));
  }
  MICA_CALL(mica_json_number(summary, "imbalance", d->partition->imbalance));
  MICA_CALL(mica_json_int(summary, "points_per_rank_min", d->stats.min_owned_points));
  MICA_CALL(mica_json_int(summary, "points_per_rank_max", d->stats.max_owned_points));
  MICA_CALL(mica_json_int(summary, "ghost_particles_max", d->stats.ghost_particles_max));
  MICA_CALL(mica_json_number(summary, "time_partition", d->stats.time_partition));
  const long local_nnz = mica_parallel_max_long(rp->solid->K->nnz);
  MICA_CALL(mica_json_int(summary, "nnz_local_max", local_nnz)); /* the largest rank's own contributions */
  /* how many times the ranks had Gmsh mesh a .geo in this process so far (one rank meshes it: geo_meshed_once) */
  return mica_json_int(summary, "gmsh_meshings", mica_parallel_sum_long(mica_mesh_geo_sessions()));
}

int run_build_memory(const RunProblem *rp, MicaJson *summary) {
  MICA_CALL(mica_json_int(summary, "peak_memory_build", rp->peak_build));
  if (rp->dist) MICA_CALL(mica_json_int(summary, "peak_memory_build_max", mica_parallel_max_long(rp->peak_build)));
  return MICA_SUCCESS;
}

/* Peak memory of the ranks (collective), at the end of a run; and once the geometry was built (run_build_memory). */
int run_parallel_memory(const RunProblem *rp, MicaJson *summary) {
  MICA_CALL(run_build_memory(rp, summary));
  if (!rp->dist) return MICA_SUCCESS;
  const long peak = mica_parallel_peak_memory(), largest = mica_parallel_max_long(peak);
  MICA_CALL(mica_json_int(summary, "peak_memory_rank0", peak));
  MICA_CALL(mica_json_int(summary, "peak_memory_rank_max", largest));
  return MICA_SUCCESS;
}

/* Per rank: what it owns and what its share of the distributed work cost it. */
enum { RANK_POINTS, RANK_BOUNDARY, RANK_OWNED, RANK_LOCAL, RANK_NNZ, RANK_WALL_CACHE, RANK_CPU_CACHE, RANK_WALL_ASSEMBLE, RANK_CPU_ASSEMBLE,
       RANK_WAIT_WALL, RANK_WAIT_CPU, RANK_PEAK, RANK_FIELDS };

static int add_rank_array(MicaJson *summary, const char *key, const double *rows, int nranks, int field) {
  MICA_CALL(mica_json_open_array(summary, key));
  for (int r = 0; r < nranks; r++) MICA_CALL(mica_json_number(summary, NULL, rows[r * RANK_FIELDS + field]));
  return mica_json_close(summary);
}

static void print_ranks(const double *rows, int nranks) {
  printf("per rank: particles owned / held (with ghosts), points (+boundary), own matrix entries, wall / CPU seconds of cache+pattern and of the assemblies "
         "(CPU without the wait), wall seconds waiting in the residual sum\n");
  for (int r = 0; r < nranks; r++) {
    const double *v = rows + r * RANK_FIELDS;
    printf("  rank %d: %8.0f / %8.0f particles  %8.0f (+%6.0f) points  nnz %10.0f  cache+pattern %7.3f / %7.3f s  "
           "assemble %8.3f / %8.3f s  "
           "wait %7.3f s\n",
           r, v[RANK_OWNED], v[RANK_LOCAL], v[RANK_POINTS], v[RANK_BOUNDARY], v[RANK_NNZ], v[RANK_WALL_CACHE], v[RANK_CPU_CACHE], v[RANK_WALL_ASSEMBLE],
           v[RANK_CPU_ASSEMBLE] - v[RANK_WAIT_CPU], v[RANK_WAIT_WALL]);
  }
  fflush(stdout);
}

int run_parallel_ranks(const RunProblem *rp, const MicaNewtonStats *stats, MicaJson *summary) {
  MICA_CALL(mica_json_number(summary, "cpu_cache_and_pattern", rp->cpu_cache_pattern));
  MICA_CALL(mica_json_number(summary, "cpu_assemble", stats->cpu_assemble));
  const MicaDistribution *d = rp->dist;
  if (!d) return MICA_SUCCESS;
  const int nranks = mica_parallel_size(), root = mica_parallel_rank() == 0;
  double mine[RANK_FIELDS], *rows = NULL;
  long calls = 0;
  mine[RANK_POINTS] = (double)d->local->nquad;
  mine[RANK_BOUNDARY] = 0;
  for (int s = 0; s < d->local->nsets; s++) mine[RANK_BOUNDARY] += (double)d->local->sets[s].n;
  mine[RANK_NNZ] = (double)rp->solid->K->nnz;
  /* the particles this rank owns and holds (owned + ghosts: the whole set with replicated data) */
  mine[RANK_OWNED] = (double)d->stats.owned_particles;
  mine[RANK_LOCAL] = (double)(d->owned ? d->nowned + d->nghost : d->nparticles);
  mine[RANK_WALL_CACHE] = rp->time_cache_pattern, mine[RANK_CPU_CACHE] = rp->cpu_cache_pattern;
  mine[RANK_WALL_ASSEMBLE] = stats->time_assemble, mine[RANK_CPU_ASSEMBLE] = stats->cpu_assemble;
  mica_parallel_residual_time(&mine[RANK_WAIT_WALL], &mine[RANK_WAIT_CPU], &calls);
  mine[RANK_PEAK] = (double)mica_parallel_peak_memory(); /* after the solve, before the outputs */
  int ierr = root ? MICA_CALLOC(rows, (long)nranks * RANK_FIELDS) : MICA_SUCCESS;
  MICA_CALL(mica_parallel_agree(ierr));
  MPI_Gather(mine, RANK_FIELDS, MPI_DOUBLE, rows, RANK_FIELDS, MPI_DOUBLE, 0, mica_parallel_comm());
  if (!root) return MICA_SUCCESS;
  print_ranks(rows, nranks);
  /* the assembly's own CPU time: without the time spent (spinning) in the residual sum */
  for (int r = 0; r < nranks; r++) rows[r * RANK_FIELDS + RANK_CPU_ASSEMBLE] -= rows[r * RANK_FIELDS + RANK_WAIT_CPU];
  ierr = add_rank_array(summary, "rank_points", rows, nranks, RANK_POINTS);
  if (!ierr) ierr = add_rank_array(summary, "rank_boundary_points", rows, nranks, RANK_BOUNDARY);
  if (!ierr) ierr = add_rank_array(summary, "rank_particles_owned", rows, nranks, RANK_OWNED);
  if (!ierr) ierr = add_rank_array(summary, "rank_particles_local", rows, nranks, RANK_LOCAL);
  if (!ierr) ierr = add_rank_array(summary, "rank_nnz", rows, nranks, RANK_NNZ);
  if (!ierr) ierr = add_rank_array(summary, "rank_cpu_cache_and_pattern", rows, nranks, RANK_CPU_CACHE);
  if (!ierr) ierr = add_rank_array(summary, "rank_cpu_assemble", rows, nranks, RANK_CPU_ASSEMBLE);
  if (!ierr) ierr = add_rank_array(summary, "rank_assemble_wait", rows, nranks, RANK_WAIT_WALL);
  if (!ierr) ierr = add_rank_array(summary, "rank_peak_memory", rows, nranks, RANK_PEAK);
  free(rows);
  return ierr;
}
