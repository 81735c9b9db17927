/* `mica run` and `mica check` under MPI (src/parallel): the deck's parallel settings, and the partition's
 * and the distributed solver's numbers in the summary and the log. Nothing here runs in a serial run. */
#include <stdio.h>
#include <string.h>

#include "run.h"

int run_parallel_distribute(const MicaDeck *deck, RunProblem *rp) {
  MicaParallelOptions opt;
  const char *kind;
  long overlap, iterations;
  memset(&opt, 0, sizeof opt);
  MICA_CALL(mica_deck_string(deck, "solver.parallel", &kind));
  MICA_CALL(mica_deck_int(deck, "solver.overlap", &overlap));
  MICA_CALL(mica_deck_float(deck, "solver.linear_rtol", &opt.rtol));
  MICA_CALL(mica_deck_int(deck, "solver.linear_max_iterations", &iterations));
  MICA_CALL(mica_deck_bool(deck, "output.monitor", &opt.verbose));
  opt.solver = strcmp(kind, "schwarz") ? MICA_PARALLEL_GATHER : MICA_PARALLEL_SCHWARZ;
  opt.overlap = (int)overlap;
  opt.max_iterations = (int)iterations;
  MICA_CALL(mica_distribution_create(rp->disc, rp->mls, &opt, &rp->dist));
  const MicaDistribution *d = rp->dist;
  printf("MPI: %d ranks, METIS edge cut %ld, imbalance %.3f; quadrature points per rank %ld to %ld, ghost particles "
         "up to %ld (partition %.3g s)\n",
         mica_parallel_size(), d->partition->edge_cut, d->partition->imbalance, d->stats.min_owned_points,
         d->stats.max_owned_points, d->stats.ghost_particles_max, d->stats.time_partition);
  fflush(stdout);
  return MICA_SUCCESS;
}

int run_parallel_totals(const RunProblem *rp, RunTotals *c) {
  MICA_CALL(mica_parallel_matrix_nnz(rp->solid->K, &c->nnz));
  c->support_entries = mica_parallel_sum_long(c->support_entries);
  c->support_points = mica_parallel_sum_long(c->support_points);
  c->max_support = mica_parallel_max_long(c->max_support);
  c->cache_bytes = mica_parallel_sum_long(c->cache_bytes);
  return MICA_SUCCESS;
}

int run_parallel_counts(const RunProblem *rp, MicaJson *summary) {
  const MicaDistribution *d = rp->dist;
  if (!d) return MICA_SUCCESS;
  MICA_CALL(mica_json_string(summary, "parallel_solver", d->opt.solver == MICA_PARALLEL_SCHWARZ ? "schwarz" : "gather"));
  MICA_CALL(mica_json_int(summary, "edge_cut", d->partition->edge_cut));
  MICA_CALL(mica_json_number(summary, "imbalance", d->partition->imbalance));
  MICA_CALL(mica_json_int(summary, "points_per_rank_min", d->stats.min_owned_points));
  MICA_CALL(mica_json_int(summary, "points_per_rank_max", d->stats.max_owned_points));
  MICA_CALL(mica_json_int(summary, "ghost_particles_max", d->stats.ghost_particles_max));
  MICA_CALL(mica_json_number(summary, "time_partition", d->stats.time_partition));
  const long local_nnz = mica_parallel_max_long(rp->solid->K->nnz);
  MICA_CALL(mica_json_int(summary, "nnz_local_max", local_nnz)); /* the largest rank's own contributions */
  return MICA_SUCCESS;
}

/* Peak memory of the ranks (collective), at the end of a run. */
int run_parallel_memory(const RunProblem *rp, MicaJson *summary) {
  if (!rp->dist) return MICA_SUCCESS;
  const long peak = mica_parallel_peak_memory(), largest = mica_parallel_max_long(peak);
  MICA_CALL(mica_json_int(summary, "peak_memory_rank0", peak));
  MICA_CALL(mica_json_int(summary, "peak_memory_rank_max", largest));
  return MICA_SUCCESS;
}

int run_parallel_solver_stats(const RunProblem *rp, MicaJson *summary) {
  const MicaDistribution *d = rp->dist;
  if (!d) return MICA_SUCCESS;
  const MicaParallelStats *st = &d->stats;
  MICA_CALL(mica_json_number(summary, "time_gather", st->time_gather));
  if (d->opt.solver != MICA_PARALLEL_SCHWARZ) return MICA_SUCCESS;
  MICA_CALL(mica_json_int(summary, "overlap", d->opt.overlap));
  MICA_CALL(mica_json_number(summary, "linear_rtol", d->opt.rtol));
  MICA_CALL(mica_json_int(summary, "krylov_solves", st->krylov_solves));
  MICA_CALL(mica_json_int(summary, "krylov_iterations", st->krylov_iterations));
  MICA_CALL(mica_json_int(summary, "krylov_iterations_max", st->krylov_max_iterations));
  MICA_CALL(mica_json_number(summary, "krylov_last_residual", st->krylov_last_residual));
  MICA_CALL(mica_json_int(summary, "subdomain_dofs_min", st->subdomain_dofs_min));
  MICA_CALL(mica_json_int(summary, "subdomain_dofs_max", st->subdomain_dofs_max));
  printf("Schwarz: %ld Krylov solves, %ld iterations (at most %ld), subdomains of %ld to %ld dofs\n",
         st->krylov_solves, st->krylov_iterations, st->krylov_max_iterations, st->subdomain_dofs_min,
         st->subdomain_dofs_max);
  return MICA_SUCCESS;
}
