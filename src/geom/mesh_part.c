/* A Gmsh mesh and its parts, for parallel.data = "distributed" (mica/geom.h, MicaMesh, MicaMeshSource): a mesh as
 * read — whole, or a region of it — with its particles (the nodes of its volume elements, in the order a serial run
 * numbers them, each keyed by its node's position in the whole mesh), and a part of one — the volume elements a rank
 * owns (by their centroids), the boundary elements on their sides, and their nodes — whose discretization is that
 * rank's volume and boundary points. A part keeps every physical group, so every rank knows every boundary set.
 *
 * A source reads a .msh file in passes, through gmsh_read_filtered, never whole: the first pass keeps no node but
 * the groups, the dimension and a sample of the nodes' coordinates (every k-th, k doubling as the sample fills: the
 * same on every rank), later passes the nodes within a box and the elements whose nodes all lie in it. A .geo is
 * meshed whole by the Gmsh library (once) and its regions are cut from it in memory, with the same results; under MPI
 * one rank has Gmsh write it to a .msh file (mica_mesh_geo_write) which every rank then reads as above. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"

struct MicaMesh {
  GmshMesh gmsh;
  long nparticles;
  double *x;           /* [nparticles·dim]: the particles (a part: none) */
  long *key;           /* [nparticles]: each one's node's position in the whole mesh */
  double element_size; /* the largest distance between two nodes of a volume element */
  long uncovered;      /* the whole mesh's uncovered boundary faces (geom_mesh_faces; a region: 0) */
};

int mica_mesh_destroy(MicaMesh **mesh) {
  if (!mesh || !*mesh) return MICA_SUCCESS;
  gmsh_free(&(*mesh)->gmsh);
  MICA_FREE((*mesh)->x);
  MICA_FREE((*mesh)->key);
  MICA_FREE(*mesh);
  return MICA_SUCCESS;
}

const long *mica_mesh_particle_keys(const MicaMesh *mesh) { return mesh->key; }
const GmshMesh *geom_mesh_of(const MicaMesh *mesh) { return &mesh->gmsh; }

int mica_mesh_dim(const MicaMesh *mesh) { return geom_mesh_dimension(&mesh->gmsh); }
long mica_mesh_num_particles(const MicaMesh *mesh) { return mesh->nparticles; }
const double *mica_mesh_particles(const MicaMesh *mesh) { return mesh->x; }
double mica_mesh_element_size(const MicaMesh *mesh) { return mesh->element_size; }

static int is_volume(const GmshMesh *g, long e, int dim) { return gmsh_element_dim(g->type[e]) == dim; }

/* The particles: the nodes of the volume elements in node order, as geom_mesh_discretize numbers them. */
static int mesh_particles(MicaMesh *mesh, int dim) {
  const GmshMesh *g = &mesh->gmsh;
  char *used = NULL;
  MICA_CALL(MICA_CALLOC(used, g->nnodes + 1));
  for (long e = 0; e < g->nelements; e++)
    if (is_volume(g, e, dim))
      for (long j = g->node_start[e]; j < g->node_start[e + 1]; j++) used[g->node[j]] = 1;
  long n = 0;
  for (long i = 0; i < g->nnodes; i++) n += used[i];
  int ierr = MICA_MALLOC(mesh->x, n * dim + 1);
  if (!ierr) ierr = MICA_MALLOC(mesh->key, n + 1);
  for (long i = 0, k = 0; !ierr && i < g->nnodes; i++)
    if (used[i]) {
      memcpy(mesh->x + k * dim, g->x + i * 3, sizeof(double) * (size_t)dim);
      mesh->key[k++] = g->node_key ? g->node_key[i] : i;
    }
  mesh->nparticles = ierr ? 0 : n;
  MICA_FREE(used);
  return ierr;
}

static void measure_elements(MicaMesh *mesh, int dim) {
  const GmshMesh *g = &mesh->gmsh;
  for (long e = 0; e < g->nelements; e++) {
    if (!is_volume(g, e, dim)) continue;
    for (long a = g->node_start[e]; a < g->node_start[e + 1]; a++)
      for (long b = a + 1; b < g->node_start[e + 1]; b++) {
        double s = 0;
        for (int i = 0; i < 3; i++) s += pow(g->x[g->node[a] * 3 + i] - g->x[g->node[b] * 3 + i], 2);
        if (sqrt(s) > mesh->element_size) mesh->element_size = sqrt(s);
      }
  }
}

int mica_mesh_read(const MicaShapeSpec *shape, MicaMesh **out) {
  MicaMesh *mesh = NULL;
  *out = NULL;
  MICA_CHECK(shape->kind == MICA_SHAPE_GMSH && shape->mesh_path && shape->mesh_path[0], MICA_ERR_INPUT,
             "gmsh: no mesh file given");
  MICA_CALL(MICA_CALLOC(mesh, 1));
  int ierr = gmsh_read(shape->mesh_path, shape->mesh_size_factor, &mesh->gmsh);
  if (ierr) { /* gmsh_read freed what it had read */
    MICA_FREE(mesh);
    return ierr;
  }
  const int dim = geom_mesh_dimension(&mesh->gmsh);
  MICA_CALL_CLEANUP(geom_mesh_check_dimension(&mesh->gmsh));
  MICA_CALL_CLEANUP(mesh_particles(mesh, dim));
  MICA_CALL_CLEANUP(geom_mesh_faces(&mesh->gmsh, dim, &mesh->uncovered, NULL));
  measure_elements(mesh, dim);
  *out = mesh;
  return MICA_SUCCESS;
cleanup:
  mica_mesh_destroy(&mesh);
  return ierr;
}

/* ---- a part ------------------------------------------------------------------------------------------------ */

/* The whole mesh's entity tables and physical groups, copied (they are small: entities, not elements). */
static int copy_groups(const GmshMesh *g, GmshMesh *p) {
  snprintf(p->path, sizeof p->path, "%s", g->path);
  p->nphysicals = g->nphysicals;
  MICA_CALL(MICA_MALLOC(p->physicals, g->nphysicals + 1));
  if (g->nphysicals) memcpy(p->physicals, g->physicals, sizeof *g->physicals * (size_t)g->nphysicals);
  for (int d = 0; d < 4; d++) {
    const long n = g->nentities[d], nphys = g->entity_phys_start[d] ? g->entity_phys_start[d][n] : 0;
    p->nentities[d] = n;
    MICA_CALL(MICA_MALLOC(p->entity_tags[d], n + 1));
    MICA_CALL(MICA_CALLOC(p->entity_phys_start[d], n + 1));
    MICA_CALL(MICA_MALLOC(p->entity_phys[d], nphys + 1));
    MICA_CALL(MICA_MALLOC(p->entity_index[d], n + 1));
    if (n) {
      memcpy(p->entity_tags[d], g->entity_tags[d], sizeof(int) * (size_t)n);
      memcpy(p->entity_phys_start[d], g->entity_phys_start[d], sizeof(long) * (size_t)(n + 1));
      memcpy(p->entity_index[d], g->entity_index[d], sizeof(GmshEntityKey) * (size_t)n);
    }
    if (nphys) memcpy(p->entity_phys[d], g->entity_phys[d], sizeof(int) * (size_t)nphys);
  }
  return MICA_SUCCESS;
}

/* The kept elements (keep[e]) and their nodes, renumbered in the whole mesh's order. */
static int copy_elements(const GmshMesh *g, const char *keep, GmshMesh *p) {
  long nelem = 0, nconn = 0, *node_map = NULL;
  for (long e = 0; e < g->nelements; e++)
    if (keep[e]) nelem++, nconn += g->node_start[e + 1] - g->node_start[e];
  MICA_CALL(gmsh_mesh_grow_elements(p, nelem));
  MICA_CALL(MICA_MALLOC(p->node, nconn + 1));
  MICA_CALL(MICA_MALLOC(node_map, g->nnodes + 1));
  for (long i = 0; i < g->nnodes; i++) node_map[i] = -1;
  for (long e = 0; e < g->nelements; e++)
    if (keep[e])
      for (long j = g->node_start[e]; j < g->node_start[e + 1]; j++) node_map[g->node[j]] = 0;
  for (long i = 0; i < g->nnodes; i++)
    if (node_map[i] == 0) node_map[i] = p->nnodes++;
  int ierr = MICA_MALLOC(p->x, p->nnodes * 3 + 1);
  if (!ierr) ierr = MICA_MALLOC(p->node_key, p->nnodes + 1);
  for (long i = 0; !ierr && i < g->nnodes; i++)
    if (node_map[i] >= 0) {
      memcpy(p->x + node_map[i] * 3, g->x + i * 3, sizeof(double) * 3);
      p->node_key[node_map[i]] = g->node_key ? g->node_key[i] : i;
    }
  for (long e = 0; !ierr && e < g->nelements; e++) {
    if (!keep[e]) continue;
    const long k = p->nelements++;
    p->type[k] = g->type[e], p->entity_dim[k] = g->entity_dim[e], p->entity_tag[k] = g->entity_tag[e];
    p->tag[k] = g->tag[e], p->line[k] = g->line ? g->line[e] : 0;
    p->node_start[k + 1] = p->node_start[k] + g->node_start[e + 1] - g->node_start[e];
    for (long j = g->node_start[e]; j < g->node_start[e + 1]; j++)
      p->node[p->node_start[k] + j - g->node_start[e]] = node_map[g->node[j]];
  }
  MICA_FREE(node_map);
  return ierr;
}

/* keep[e]: a volume element whose centroid `keep` accepts; a boundary element if it is a side of one (one that is
 * a side of none goes by its own centroid, so that one rank reports it as serially). *uncovered: the uncovered
 * boundary faces whose centroids `keep` accepts (one face table for both). */
static int choose_elements(const GmshMesh *g, int dim, MicaMeshKeep keep, void *ctx, char *chosen, long *uncovered) {
  long *side_of = NULL;
  MICA_CALL(MICA_MALLOC(side_of, g->nelements + 1));
  int ierr = geom_mesh_faces_where(g, dim, keep, ctx, uncovered, side_of);
  for (long e = 0; !ierr && e < g->nelements; e++) {
    double c[3];
    geom_mesh_centroid(g, e, c);
    chosen[e] = is_volume(g, e, dim) && keep(c, ctx);
  }
  for (long e = 0; !ierr && e < g->nelements; e++) {
    if (gmsh_element_dim(g->type[e]) != dim - 1) continue;
    double c[3];
    geom_mesh_centroid(g, e, c);
    chosen[e] = side_of[e] >= 0 ? chosen[side_of[e]] : keep(c, ctx);
  }
  MICA_FREE(side_of);
  return ierr;
}

int mica_mesh_part(const MicaMesh *whole, MicaMeshKeep keep, void *ctx, MicaMesh **out) {
  const GmshMesh *g = &whole->gmsh;
  const int dim = geom_mesh_dimension(g);
  MicaMesh *part = NULL;
  char *chosen = NULL;
  *out = NULL;
  MICA_CALL(MICA_CALLOC(part, 1));
  int ierr = MICA_CALLOC(chosen, g->nelements + 1);
  if (!ierr) ierr = choose_elements(g, dim, keep, ctx, chosen, &part->uncovered);
  if (!ierr) ierr = copy_groups(g, &part->gmsh);
  if (!ierr) ierr = copy_elements(g, chosen, &part->gmsh);
  MICA_FREE(chosen);
  part->gmsh.part_dim = dim;
  part->gmsh.part_uncovered = part->uncovered; /* its share: over a split, the shares add up to the whole's */
  part->element_size = whole->element_size;
  if (!ierr) ierr = MICA_MALLOC(part->x, 1);
  if (!ierr) ierr = MICA_MALLOC(part->key, 1);
  if (ierr) mica_mesh_destroy(&part);
  *out = part;
  return ierr;
}

int mica_discretization_create_mesh(const MicaMesh *mesh, const MicaCellSpec *cells, int output_mesh,
                                    MicaDiscretization **disc) {
  MicaDiscretization *d = NULL;
  *disc = NULL;
  MICA_CALL(MICA_CALLOC(d, 1));
  const int boundary_order = cells->boundary_order == 0 ? cells->order : cells->boundary_order;
  int ierr = geom_mesh_discretize(&mesh->gmsh, cells->order, boundary_order, d);
  if (!ierr && output_mesh) ierr = geom_mesh_cells(&mesh->gmsh, d->dim, &d->mesh);
  if (ierr) mica_discretization_destroy(&d);
  *disc = d;
  return ierr;
}

/* ---- regions and the source ------------------------------------------------------------------------------ */

typedef struct {
  double lo[3], hi[3];
} Box;

static int in_box(const double x[3], void *ctx) {
  const Box *b = ctx;
  for (int d = 0; d < 3; d++)
    if (!(x[d] >= b->lo[d] && x[d] < b->hi[d])) return 0;
  return 1;
}

/* A region's MicaMesh from its GmshMesh (taken): its particles, keys and element size; dim: the whole mesh's. */
static int region_finish(GmshMesh *g, int dim, MicaMesh **out) {
  MicaMesh *mesh = NULL;
  *out = NULL;
  int ierr = MICA_CALLOC(mesh, 1);
  if (ierr) {
    gmsh_free(g);
    return ierr;
  }
  mesh->gmsh = *g;
  memset(g, 0, sizeof *g);
  mesh->gmsh.part_dim = dim, mesh->gmsh.part_uncovered = 0;
  ierr = mesh_particles(mesh, dim);
  measure_elements(mesh, dim);
  if (ierr) mica_mesh_destroy(&mesh);
  *out = mesh;
  return ierr;
}

/* The nodes of `whole` in the box and the elements whose nodes all are, as gmsh_read_filtered reads them from a
 * file (a .geo meshed whole). */
static int cut_region(const GmshMesh *whole, const Box *box, GmshMesh *g) {
  char *keep = NULL, *node_in = NULL;
  MICA_CALL(MICA_CALLOC(keep, whole->nelements + 1));
  int ierr = MICA_CALLOC(node_in, whole->nnodes + 1);
  for (long i = 0; !ierr && i < whole->nnodes; i++) node_in[i] = (char)in_box(whole->x + i * 3, (void *)box);
  for (long e = 0; !ierr && e < whole->nelements; e++) {
    keep[e] = 1;
    for (long j = whole->node_start[e]; j < whole->node_start[e + 1]; j++) keep[e] &= node_in[whole->node[j]];
  }
  if (!ierr) ierr = copy_groups(whole, g);
  if (!ierr) ierr = copy_elements(whole, keep, g); /* the nodes of the kept elements (others are no particles) */
  MICA_FREE(keep);
  MICA_FREE(node_in);
  return ierr;
}

struct MicaMeshSource {
  char path[512];
  int dim;
  MicaMesh *whole; /* a .geo: meshed once; NULL for a .msh file, read in passes */
  MicaMesh *names; /* no elements: the groups (every set's name) */
  long nsample;
  double *sample;  /* [nsample·dim] node coordinates, the same on every rank */
  double lower[3], upper[3]; /* the nodes' bounding box */
  long nodes, volume_elements, boundary_elements; /* counted by the first pass (a 2.2 file: an element once per
                                                     physical group it is in) */
};

enum { SAMPLE_MAX = 1 << 18 }; /* cuts on 2^18 samples balance the boxes' counts to about 1/√(2^18/P): 3 % at P = 256 */

typedef struct {
  double *x; /* [2 SAMPLE_MAX · 3] */
  long n, seen, stride;
  double lower[3], upper[3];
} Sampler;

static int sample_node(const double x[3], void *ctx) {
  Sampler *s = ctx;
  for (int d = 0; d < 3; d++) s->lower[d] = fmin(s->lower[d], x[d]), s->upper[d] = fmax(s->upper[d], x[d]);
  if (s->seen++ % s->stride) return 0;
  memcpy(s->x + s->n++ * 3, x, sizeof(double) * 3);
  if (s->n == 2 * SAMPLE_MAX) { /* full: keep every other one, take every 2k-th from now on */
    for (long i = 0; i < SAMPLE_MAX; i++) memcpy(s->x + i * 3, s->x + 2 * i * 3, sizeof(double) * 3);
    s->n = SAMPLE_MAX, s->stride *= 2;
  }
  return 0;
}

static int keep_nothing(const double *x, void *ctx) {
  (void)x, (void)ctx;
  return 0;
}

/* The first pass over a .msh file: its groups and dimension, and the sample. */
static int first_pass(MicaMeshSource *src) {
  Sampler sampler = {.stride = 1, .lower = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, .upper = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  GmshFilter filter = {.keep = sample_node, .ctx = &sampler};
  GmshMesh g;
  MICA_CALL(MICA_MALLOC(sampler.x, 2L * SAMPLE_MAX * 3));
  int ierr = gmsh_read_filtered(src->path, &filter, &g);
  if (!ierr) {
    g.part_dim = filter.max_dim; /* the dimension of the file's elements, none of which is kept */
    ierr = geom_mesh_check_dimension(&g);
    if (ierr) gmsh_free(&g);
    else ierr = region_finish(&g, filter.max_dim, &src->names);
  }
  src->dim = filter.max_dim, src->nsample = sampler.n;
  src->nodes = filter.nodes_read;
  src->volume_elements = filter.elements_of_dim[src->dim & 3];
  src->boundary_elements = src->dim >= 1 ? filter.elements_of_dim[(src->dim - 1) & 3] : 0;
  memcpy(src->lower, sampler.lower, sizeof src->lower);
  memcpy(src->upper, sampler.upper, sizeof src->upper);
  if (!ierr) ierr = MICA_MALLOC(src->sample, sampler.n * src->dim + 1);
  for (long i = 0; !ierr && i < sampler.n; i++)
    memcpy(src->sample + i * src->dim, sampler.x + i * 3, sizeof(double) * (size_t)src->dim);
  MICA_FREE(sampler.x);
  return ierr;
}

/* A .geo's: the whole mesh's groups and every k-th particle. */
static int whole_sample(MicaMeshSource *src) {
  const MicaMesh *w = src->whole;
  const long stride = w->nparticles / SAMPLE_MAX + 1;
  src->dim = mica_mesh_dim(w);
  src->nodes = w->nparticles;
  for (long e = 0; e < w->gmsh.nelements; e++) {
    src->volume_elements += gmsh_element_dim(w->gmsh.type[e]) == src->dim;
    src->boundary_elements += gmsh_element_dim(w->gmsh.type[e]) == src->dim - 1;
  }
  src->nsample = (w->nparticles + stride - 1) / stride;
  MICA_CALL(MICA_MALLOC(src->sample, src->nsample * src->dim + 1));
  for (long i = 0; i < src->nsample; i++)
    memcpy(src->sample + i * src->dim, w->x + i * stride * src->dim, sizeof(double) * (size_t)src->dim);
  for (int d = 0; d < 3; d++) src->lower[d] = HUGE_VAL, src->upper[d] = -HUGE_VAL;
  for (long i = 0; i < w->gmsh.nnodes; i++)
    for (int d = 0; d < 3; d++)
      src->lower[d] = fmin(src->lower[d], w->gmsh.x[i * 3 + d]), src->upper[d] = fmax(src->upper[d], w->gmsh.x[i * 3 + d]);
  return mica_mesh_part(w, keep_nothing, NULL, &src->names);
}

int mica_mesh_source_open(const MicaShapeSpec *shape, MicaMeshSource **out) {
  MicaMeshSource *src = NULL;
  *out = NULL;
  MICA_CHECK(shape->kind == MICA_SHAPE_GMSH && shape->mesh_path && shape->mesh_path[0], MICA_ERR_INPUT,
             "gmsh: no mesh file given");
  MICA_CALL(MICA_CALLOC(src, 1));
  snprintf(src->path, sizeof src->path, "%s", shape->mesh_path);
  int ierr = MICA_SUCCESS;
  if (gmsh_is_geo(shape->mesh_path)) {
    ierr = mica_mesh_read(shape, &src->whole);
    if (!ierr) ierr = whole_sample(src);
  } else {
    if (shape->mesh_size_factor != 0)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s: a mesh size factor applies to a .geo "
                            "that mica meshes, not to a mesh file", shape->mesh_path);
    else ierr = first_pass(src);
  }
  if (ierr) mica_mesh_source_close(&src);
  *out = src;
  return ierr;
}

int mica_mesh_geo_write(const MicaShapeSpec *shape, const char *msh) {
  MICA_CHECK(shape->kind == MICA_SHAPE_GMSH && shape->mesh_path && gmsh_is_geo(shape->mesh_path) && msh,
             MICA_ERR_ARGUMENT, "mica_mesh_geo_write: no .geo given");
  return gmsh_geo_write(shape->mesh_path, shape->mesh_size_factor, msh);
}

long mica_mesh_geo_sessions(void) { return gmsh_geo_sessions(); }
int mica_mesh_is_geo(const char *path) { return path && gmsh_is_geo(path); }

int mica_mesh_source_close(MicaMeshSource **src) {
  if (!src || !*src) return MICA_SUCCESS;
  mica_mesh_destroy(&(*src)->whole);
  mica_mesh_destroy(&(*src)->names);
  MICA_FREE((*src)->sample);
  MICA_FREE(*src);
  return MICA_SUCCESS;
}

int mica_mesh_source_dim(const MicaMeshSource *src) { return src->dim; }
const MicaMesh *mica_mesh_source_names(const MicaMeshSource *src) { return src->names; }

void mica_mesh_source_counts(const MicaMeshSource *src, long *nodes, long *volume_elements, long *boundary_elements) {
  *nodes = src->nodes, *volume_elements = src->volume_elements, *boundary_elements = src->boundary_elements;
}

void mica_mesh_source_bounds(const MicaMeshSource *src, double lower[3], double upper[3]) {
  memcpy(lower, src->lower, sizeof src->lower);
  memcpy(upper, src->upper, sizeof src->upper);
}

const double *mica_mesh_source_sample(const MicaMeshSource *src, long *n) {
  *n = src->nsample;
  return src->sample;
}

int mica_mesh_source_region(const MicaMeshSource *src, const double lo[3], const double hi[3], MicaMesh **region) {
  Box box;
  GmshMesh g;
  memset(&g, 0, sizeof g);
  for (int d = 0; d < 3; d++) {
    box.lo[d] = d < src->dim ? lo[d] : -HUGE_VAL;
    box.hi[d] = d < src->dim ? hi[d] : HUGE_VAL;
  }
  *region = NULL;
  if (src->whole) {
    snprintf(g.path, sizeof g.path, "%s", src->path);
    const int ierr = cut_region(&src->whole->gmsh, &box, &g);
    if (ierr) {
      gmsh_free(&g);
      return ierr;
    }
  } else {
    GmshFilter filter = {.keep = in_box, .ctx = &box};
    MICA_CALL(gmsh_read_filtered(src->path, &filter, &g));
  }
  return region_finish(&g, src->dim, region);
}
