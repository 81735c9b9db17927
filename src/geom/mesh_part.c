/* A Gmsh mesh and its parts, for parallel.data = "distributed" (mica/geom.h, MicaMesh): the whole mesh as read,
 * its particles (the nodes of its volume elements, in the order a serial run numbers them), and a part of it —
 * the volume elements a rank owns (by their centroids), the boundary elements on their sides, and their nodes —
 * whose discretization is that rank's volume and boundary points. A part keeps the whole mesh's physical groups, so
 * every rank knows every boundary set's name, and the whole mesh's count of uncovered boundary faces. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"

struct MicaMesh {
  GmshMesh gmsh;
  long nparticles;
  double *x; /* [nparticles·dim]: the particles (a part: none) */
  double element_size; /* the largest distance between two nodes of a volume element */
  long uncovered;      /* the whole mesh's uncovered boundary faces (geom_mesh_faces) */
};

int mica_mesh_destroy(MicaMesh **mesh) {
  if (!mesh || !*mesh) return MICA_SUCCESS;
  gmsh_free(&(*mesh)->gmsh);
  MICA_FREE((*mesh)->x);
  MICA_FREE(*mesh);
  return MICA_SUCCESS;
}

int mica_mesh_dim(const MicaMesh *mesh) { return geom_mesh_dimension(&mesh->gmsh); }
long mica_mesh_num_particles(const MicaMesh *mesh) { return mesh->nparticles; }
const double *mica_mesh_particles(const MicaMesh *mesh) { return mesh->x; }
double mica_mesh_element_size(const MicaMesh *mesh) { return mesh->element_size; }

static int is_volume(const GmshMesh *g, long e, int dim) { return gmsh_element_dim(g->type[e]) == dim; }

/* The particles: the nodes of the volume elements in node order, as geom_mesh_discretize numbers them. */
static int whole_particles(MicaMesh *mesh, int dim) {
  const GmshMesh *g = &mesh->gmsh;
  char *used = NULL;
  MICA_CALL(MICA_CALLOC(used, g->nnodes + 1));
  for (long e = 0; e < g->nelements; e++)
    if (is_volume(g, e, dim))
      for (long j = g->node_start[e]; j < g->node_start[e + 1]; j++) used[g->node[j]] = 1;
  long n = 0;
  for (long i = 0; i < g->nnodes; i++) n += used[i];
  int ierr = MICA_MALLOC(mesh->x, n * dim + 1);
  for (long i = 0, k = 0; !ierr && i < g->nnodes; i++)
    if (used[i]) memcpy(mesh->x + k++ * dim, g->x + i * 3, sizeof(double) * (size_t)dim);
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
  MICA_CALL_CLEANUP(whole_particles(mesh, dim));
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
  MICA_CALL(MICA_MALLOC(p->type, nelem + 1));
  MICA_CALL(MICA_MALLOC(p->entity_dim, nelem + 1));
  MICA_CALL(MICA_MALLOC(p->entity_tag, nelem + 1));
  MICA_CALL(MICA_MALLOC(p->tag, nelem + 1));
  MICA_CALL(MICA_MALLOC(p->line, nelem + 1));
  MICA_CALL(MICA_CALLOC(p->node_start, nelem + 1));
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
      p->node_key[node_map[i]] = i;
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
 * a side of none goes by its own centroid, so that one rank reports it as serially). */
static int choose_elements(const GmshMesh *g, int dim, MicaMeshKeep keep, void *ctx, char *chosen) {
  long *side_of = NULL;
  MICA_CALL(MICA_MALLOC(side_of, g->nelements + 1));
  int ierr = geom_mesh_faces(g, dim, NULL, side_of);
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
  if (!ierr) ierr = choose_elements(g, dim, keep, ctx, chosen);
  if (!ierr) ierr = copy_groups(g, &part->gmsh);
  if (!ierr) ierr = copy_elements(g, chosen, &part->gmsh);
  MICA_FREE(chosen);
  part->gmsh.part_dim = dim;
  part->gmsh.part_uncovered = part->uncovered = whole->uncovered;
  part->element_size = whole->element_size;
  if (!ierr) ierr = MICA_MALLOC(part->x, 1);
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
