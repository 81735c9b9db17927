/* The discretization of a Gmsh mesh (docs/theory.md §geometry, "Gmsh meshes"). The dimension is the highest
 * element dimension. Nodes of the volume elements are the particles; each volume element is an integration
 * cell, isoparametric linear, with the collapsed Gauss rule (triangle, tetrahedron) or the tensor Gauss
 * rule (quadrangle, hexahedron) of `order` points per direction: weight = w_ref × |det ∂x/∂r|. Every
 * physical group of dimension dim − 1 is a boundary set named by $PhysicalNames (or by its tag number
 * when unnamed); its elements are the set's boundary elements, integrated with `boundary_order` points
 * per direction, and their normals point away from the centroid of the volume element they bound.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"
#include "mica/sort.h"

enum { TYPE_MAX = 16, NODES_MAX = 8 };

/* ---- reference elements ---- */

/* Corners of the quadrangle and hexahedron on [0,1]^d in Gmsh's node order. */
static const int hex_corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                     {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

/* Shape functions N_a(r) and dN[a*3 + k] = ∂N_a/∂r_k of a linear element. */
static void shape_functions(int type, const double *r, double *N, double *dN) {
  memset(dN, 0, NODES_MAX * 3 * sizeof *dN);
  switch (type) {
  case GMSH_LINE2:
    N[0] = 1.0 - r[0], N[1] = r[0];
    dN[0] = -1.0, dN[3] = 1.0;
    break;
  case GMSH_TRI3:
  case GMSH_TET4: {
    const int d = type == GMSH_TRI3 ? 2 : 3;
    N[0] = 1.0;
    for (int k = 0; k < d; k++) {
      N[0] -= r[k];
      N[k + 1] = r[k];
      dN[k] = -1.0;
      dN[(k + 1) * 3 + k] = 1.0;
    }
    break;
  }
  case GMSH_QUAD4:
  case GMSH_HEX8: {
    const int d = type == GMSH_QUAD4 ? 2 : 3, n = type == GMSH_QUAD4 ? 4 : 8;
    for (int a = 0; a < n; a++) {
      double f[3], df[3];
      for (int k = 0; k < d; k++) {
        f[k] = hex_corner[a][k] ? r[k] : 1.0 - r[k];
        df[k] = hex_corner[a][k] ? 1.0 : -1.0;
      }
      N[a] = 1.0;
      for (int k = 0; k < d; k++) N[a] *= f[k];
      for (int k = 0; k < d; k++) {
        double p = df[k];
        for (int m = 0; m < d; m++)
          if (m != k) p *= f[m];
        dN[a * 3 + k] = p;
      }
    }
    break;
  }
  default: break;
  }
}

/* A quadrature rule on a reference element: points r[n*3] and weights. */
typedef struct {
  long n;
  double *r, *w;
} Rule;

static int tensor_rule(int dim, int order, Rule *rule) {
  double u[GEOM_GAUSS_MAX], wu[GEOM_GAUSS_MAX];
  MICA_CALL(geom_gauss_unit(order, u, wu));
  rule->n = dim == 1 ? order : dim == 2 ? order * order : (long)order * order * order;
  MICA_CALL(MICA_CALLOC(rule->r, rule->n * 3));
  MICA_CALL(MICA_MALLOC(rule->w, rule->n));
  for (long g = 0; g < rule->n; g++) {
    long k = g;
    rule->w[g] = 1.0;
    for (int d = 0; d < dim; d++, k /= order) {
      rule->r[g * 3 + d] = u[k % order];
      rule->w[g] *= wu[k % order];
    }
  }
  return MICA_SUCCESS;
}

static int simplex_rule(int dim, int order, Rule *rule) {
  double *r = NULL;
  int ierr = MICA_SUCCESS;
  rule->n = dim == 2 ? order * order : (long)order * order * order;
  MICA_CALL(MICA_CALLOC(rule->r, rule->n * 3));
  MICA_CALL(MICA_MALLOC(rule->w, rule->n));
  MICA_CALL(MICA_MALLOC(r, rule->n * dim));
  if (dim == 2)
    MICA_CALL_CLEANUP(mica_gauss_triangle(order, r, rule->w));
  else
    MICA_CALL_CLEANUP(mica_gauss_tetrahedron(order, r, rule->w));
  for (long g = 0; g < rule->n; g++)
    for (int d = 0; d < dim; d++) rule->r[g * 3 + d] = r[g * dim + d];
cleanup:
  MICA_FREE(r);
  return ierr;
}

static int make_rule(int type, int order, Rule *rule) {
  if (type == GMSH_TRI3 || type == GMSH_TET4) return simplex_rule(gmsh_element_dim(type), order, rule);
  return tensor_rule(gmsh_element_dim(type), order, rule);
}

static void free_rules(Rule rules[TYPE_MAX]) {
  for (int t = 0; t < TYPE_MAX; t++) {
    MICA_FREE(rules[t].r);
    MICA_FREE(rules[t].w);
  }
}

/* ---- element geometry ---- */

/* x(r) = Σ N_a x_a and the tangents tang[i*3 + k] = ∂x_i/∂r_k of element e (3 coordinates). */
static void element_map(const GmshMesh *mesh, long e, const double *r, double *x, double *tang, double *N) {
  double dN[NODES_MAX * 3];
  const long *node = &mesh->node[mesh->node_start[e]];
  const int n = gmsh_element_nodes(mesh->type[e]);
  shape_functions(mesh->type[e], r, N, dN);
  memset(tang, 0, 9 * sizeof *tang);
  for (int i = 0; i < 3; i++) {
    x[i] = 0.0;
    for (int a = 0; a < n; a++) {
      const double xa = mesh->x[node[a] * 3 + i];
      x[i] += N[a] * xa;
      for (int k = 0; k < 3; k++) tang[i * 3 + k] += dN[a * 3 + k] * xa;
    }
  }
}

void geom_mesh_centroid(const GmshMesh *mesh, long e, double c[3]) {
  const long *node = &mesh->node[mesh->node_start[e]];
  const int n = gmsh_element_nodes(mesh->type[e]);
  c[0] = c[1] = c[2] = 0.0;
  for (int a = 0; a < n; a++)
    for (int i = 0; i < 3; i++) c[i] += mesh->x[node[a] * 3 + i] / n;
}

/* det ∂x/∂r of a volume element (its first dim coordinates). */
static double volume_det(int dim, const double *tang) {
  double jac[9];
  for (int i = 0; i < dim; i++)
    for (int k = 0; k < dim; k++) jac[i * dim + k] = tang[i * 3 + k];
  return geom_det(dim, jac);
}

/* The unnormalized normal of a boundary element: (t_y, −t_x) of a line in 2-D, t_1 × t_2 in 3-D. */
static void face_normal(int dim, const double *tang, double *n) {
  if (dim == 2) {
    n[0] = tang[3], n[1] = -tang[0], n[2] = 0.0;
    return;
  }
  n[0] = tang[3] * tang[7] - tang[6] * tang[4];
  n[1] = tang[6] * tang[1] - tang[0] * tang[7];
  n[2] = tang[0] * tang[4] - tang[3] * tang[1];
}

/* ---- volume ---- */

int geom_mesh_dimension(const GmshMesh *mesh) {
  if (mesh->part_dim) return mesh->part_dim;
  int dim = 0;
  for (long e = 0; e < mesh->nelements; e++)
    if (gmsh_element_dim(mesh->type[e]) > dim) dim = gmsh_element_dim(mesh->type[e]);
  return dim;
}

static int is_volume(const GmshMesh *mesh, long e, int dim) { return gmsh_element_dim(mesh->type[e]) == dim; }

/* Particles: the nodes of volume elements, in node order. */
static int mesh_particles(const GmshMesh *mesh, int dim, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  char *used = NULL;
  MICA_CALL(MICA_CALLOC(used, mesh->nnodes));
  for (long e = 0; e < mesh->nelements; e++)
    if (is_volume(mesh, e, dim))
      for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++) used[mesh->node[j]] = 1;
  long n = 0;
  for (long i = 0; i < mesh->nnodes; i++) n += used[i];
  MICA_CALL_CLEANUP(MICA_MALLOC(disc->x, n * dim));
  disc->nparticles = 0;
  for (long i = 0; i < mesh->nnodes; i++)
    if (used[i]) {
      for (int d = 0; d < dim; d++) disc->x[disc->nparticles * dim + d] = mesh->x[i * 3 + d];
      disc->nparticles++;
    }
cleanup:
  MICA_FREE(used);
  return ierr;
}

/* A size scale of element e: the largest distance of a node from the first. */
static double element_size(const GmshMesh *mesh, long e) {
  const long *node = &mesh->node[mesh->node_start[e]];
  double h = 0.0;
  for (int a = 1; a < gmsh_element_nodes(mesh->type[e]); a++) {
    double s = 0.0;
    for (int i = 0; i < 3; i++) s += pow(mesh->x[node[a] * 3 + i] - mesh->x[node[0] * 3 + i], 2);
    h = fmax(h, sqrt(s));
  }
  return h;
}

static int mesh_volume(const GmshMesh *mesh, int dim, Rule rules[TYPE_MAX], MicaDiscretization *disc) {
  long ncells = 0, nquad = 0;
  for (long e = 0; e < mesh->nelements; e++)
    if (is_volume(mesh, e, dim)) ncells++, nquad += rules[mesh->type[e]].n;
  disc->ncells = ncells;
  disc->nquad = nquad;
  MICA_CALL(MICA_MALLOC(disc->qx, nquad * dim));
  MICA_CALL(MICA_MALLOC(disc->qw, nquad));
  MICA_CALL(MICA_MALLOC(disc->qcell, nquad)); /* the element of each point (a cell pressure groups by it) */
  long q = 0, cell = 0;
  disc->volume = 0.0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (!is_volume(mesh, e, dim)) continue;
    for (long g = 0; g < rules[mesh->type[e]].n; g++) disc->qcell[q + g] = cell;
    cell++;
    const Rule *rule = &rules[mesh->type[e]];
    const double tiny = 1e-12 * pow(element_size(mesh, e), dim);
    for (long g = 0; g < rule->n; g++, q++) {
      double x[3], tang[9], N[NODES_MAX];
      element_map(mesh, e, &rule->r[g * 3], x, tang, N);
      const double det = fabs(volume_det(dim, tang));
      if (!(det > tiny)) {
        char where[600];
        gmsh_where(mesh, e, where, sizeof where);
        MICA_ERROR(MICA_ERR_INPUT, "%s: element %ld is degenerate (zero %s)", where, mesh->tag[e],
                   dim == 2 ? "area" : "volume");
      }
      for (int d = 0; d < dim; d++) disc->qx[q * dim + d] = x[d];
      disc->qw[q] = rule->w[g] * det;
      disc->volume += disc->qw[q];
    }
  }
  return MICA_SUCCESS;
}

/* ---- faces of volume elements, to find the element a boundary element bounds ---- */

typedef struct {
  long key[4]; /* sorted node indices, padded with −1 */
  long element;
} FaceKey;

static int compare_face(const void *a, const void *b) {
  const long *x = ((const FaceKey *)a)->key, *y = ((const FaceKey *)b)->key;
  for (int i = 0; i < 4; i++)
    if (x[i] != y[i]) return (x[i] > y[i]) - (x[i] < y[i]);
  return 0;
}

static FaceKey make_key(const long *nodes, int n, long element) {
  FaceKey f = {.key = {-1, -1, -1, -1}, .element = element};
  for (int i = 0; i < n; i++) f.key[i] = nodes[i];
  qsort(f.key, (size_t)n, sizeof f.key[0], mica_compare_long);
  return f;
}

/* Local node lists of the faces (edges in 2-D) of each volume type. */
typedef struct {
  int nfaces, size;
  int nodes[6][4];
} FaceList;

static const FaceList *element_faces(int type) {
  static const FaceList tri = {3, 2, {{0, 1}, {1, 2}, {2, 0}}};
  static const FaceList quad = {4, 2, {{0, 1}, {1, 2}, {2, 3}, {3, 0}}};
  static const FaceList tet = {4, 3, {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
  static const FaceList hex = {
      6, 4, {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}};
  switch (type) {
  case GMSH_TRI3: return &tri;
  case GMSH_QUAD4: return &quad;
  case GMSH_TET4: return &tet;
  default: return &hex;
  }
}

static int face_table(const GmshMesh *mesh, int dim, FaceKey **table, long *n) {
  long count = 0;
  for (long e = 0; e < mesh->nelements; e++)
    if (is_volume(mesh, e, dim)) count += element_faces(mesh->type[e])->nfaces;
  MICA_CALL(MICA_MALLOC(*table, count));
  *n = 0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (!is_volume(mesh, e, dim)) continue;
    const FaceList *fl = element_faces(mesh->type[e]);
    const long *node = &mesh->node[mesh->node_start[e]];
    for (int f = 0; f < fl->nfaces; f++) {
      long nodes[4];
      for (int i = 0; i < fl->size; i++) nodes[i] = node[fl->nodes[f][i]];
      (*table)[(*n)++] = make_key(nodes, fl->size, e);
    }
  }
  qsort(*table, (size_t)*n, sizeof **table, compare_face);
  return MICA_SUCCESS;
}

/* ---- boundary sets ---- */

typedef struct {
  const GmshMesh *mesh;
  int dim;
  const Rule *rules;
  const FaceKey *faces;
  long nfaces;
  int (*mine)(const double *centroid, void *ctx); /* count_uncovered: the faces whose centroids it accepts (NULL: all) */
  void *mine_ctx;
} MeshContext;

/* The centroid of a face (its key's nodes). */
static void face_centroid(const GmshMesh *mesh, const FaceKey *f, double c[3]) {
  int n = 0;
  c[0] = c[1] = c[2] = 0;
  for (int a = 0; a < 4 && f->key[a] >= 0; a++, n++)
    for (int i = 0; i < 3; i++) c[i] += mesh->x[f->key[a] * 3 + i];
  for (int i = 0; i < 3; i++) c[i] /= n ? n : 1;
}

static int has_physical(const GmshMesh *mesh, long e, int phys) {
  const int *tags;
  const long n = gmsh_entity_physicals(mesh, mesh->entity_dim[e], mesh->entity_tag[e], &tags);
  for (long k = 0; k < n; k++)
    if (tags[k] == phys) return 1;
  return 0;
}

static int in_set(const MeshContext *ctx, long e, int phys) {
  return gmsh_element_dim(ctx->mesh->type[e]) == ctx->dim - 1 && has_physical(ctx->mesh, e, phys);
}

/* +1 or −1: the sign that makes the element's normal point away from the volume element it bounds. */
static int normal_sign(const MeshContext *ctx, const char *set, long e, double *sign) {
  const GmshMesh *mesh = ctx->mesh;
  const int n = gmsh_element_nodes(mesh->type[e]);
  const FaceKey key = make_key(&mesh->node[mesh->node_start[e]], n, -1);
  const FaceKey *hit = bsearch(&key, ctx->faces, (size_t)ctx->nfaces, sizeof key, compare_face);
  if (!hit) {
    char where[600];
    gmsh_where(mesh, e, where, sizeof where);
    MICA_ERROR(MICA_ERR_INPUT, "%s: element %ld of boundary set '%s' is not a side of any %d-D element", where,
               mesh->tag[e], set, ctx->dim);
  }
  const double center[3] = {1.0 / 3.0, 1.0 / 3.0, 0.0}, square_center[3] = {0.5, 0.5, 0.0};
  double x[3], tang[9], N[NODES_MAX], nrm[3], c[3];
  element_map(mesh, e, mesh->type[e] == GMSH_TRI3 ? center : square_center, x, tang, N);
  face_normal(ctx->dim, tang, nrm);
  geom_mesh_centroid(mesh, hit->element, c);
  double dot = 0.0;
  for (int i = 0; i < ctx->dim; i++) dot += (x[i] - c[i]) * nrm[i];
  *sign = dot >= 0 ? 1.0 : -1.0;
  return MICA_SUCCESS;
}

/* The set's distinct nodes (sorted) as its vertices, and each element's vertex indices. */
static int set_vertices(const MeshContext *ctx, int phys, MicaBoundarySet *set, long **nodes) {
  const GmshMesh *mesh = ctx->mesh;
  long n = 0;
  MICA_CALL(MICA_MALLOC(*nodes, set->nelements * set->element_size));
  for (long e = 0; e < mesh->nelements; e++)
    if (in_set(ctx, e, phys))
      for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++) (*nodes)[n++] = mesh->node[j];
  qsort(*nodes, (size_t)n, sizeof **nodes, mica_compare_long);
  long unique = 0;
  for (long i = 0; i < n; i++)
    if (unique == 0 || (*nodes)[i] != (*nodes)[unique - 1]) (*nodes)[unique++] = (*nodes)[i];
  set->nvertices = unique;
  return MICA_SUCCESS;
}

/* Quadrature points of boundary element e (set element number k). */
static int element_points(const MeshContext *ctx, long e, long k, MicaBoundarySet *set, long *q) {
  const GmshMesh *mesh = ctx->mesh;
  const int dim = ctx->dim, n = gmsh_element_nodes(mesh->type[e]);
  const Rule *rule = &ctx->rules[mesh->type[e]];
  double sign = 1.0;
  MICA_CALL(normal_sign(ctx, set->name, e, &sign));
  for (long g = 0; g < rule->n; g++, (*q)++) {
    double x[3], tang[9], N[NODES_MAX], nrm[3];
    element_map(mesh, e, &rule->r[g * 3], x, tang, N);
    face_normal(dim, tang, nrm);
    const double len = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    if (!(len > 0)) {
      char where[600];
      gmsh_where(mesh, e, where, sizeof where);
      MICA_ERROR(MICA_ERR_INPUT, "%s: boundary element %ld of set '%s' is degenerate", where, mesh->tag[e],
                 set->name);
    }
    for (int d = 0; d < dim; d++) {
      set->x[*q * dim + d] = x[d];
      set->normal[*q * dim + d] = sign * nrm[d] / len;
    }
    set->w[*q] = rule->w[g] * len;
    set->element[*q] = k;
    for (int a = 0; a < n; a++) set->lambda_N[*q * 4 + a] = N[a];
  }
  return MICA_SUCCESS;
}

/* Counts the set's elements and points; 3-D sets must not mix triangles and quadrangles. */
static int count_set(const MeshContext *ctx, int phys, const char *name, long *nelem, long *npts, int *size) {
  const GmshMesh *mesh = ctx->mesh;
  *nelem = *npts = 0, *size = 0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (!in_set(ctx, e, phys)) continue;
    const int n = gmsh_element_nodes(mesh->type[e]);
    if (*size && n != *size) {
      char where[600];
      gmsh_where(mesh, e, where, sizeof where);
      MICA_ERROR(MICA_ERR_INPUT,
                 "%s: boundary set '%s' mixes triangles and quadrangles, which mica does not support in one set",
                 where, name);
    }
    *size = n;
    (*nelem)++;
    *npts += ctx->rules[mesh->type[e]].n;
  }
  if (*size == 0) *size = ctx->dim == 2 ? 2 : 3;
  return MICA_SUCCESS;
}

static int build_set(const MeshContext *ctx, int phys, const char *name, MicaBoundarySet *set) {
  int ierr = MICA_SUCCESS, size;
  const GmshMesh *mesh = ctx->mesh;
  const int dim = ctx->dim;
  long *nodes = NULL, nelem, npts, q = 0, k = 0;
  snprintf(set->name, sizeof set->name, "%s", name);
  MICA_CALL(count_set(ctx, phys, name, &nelem, &npts, &size));
  set->nelements = nelem, set->element_size = size;
  MICA_CALL_CLEANUP(set_vertices(ctx, phys, set, &nodes));
  MICA_CALL_CLEANUP(geom_set_alloc(set, dim, npts, nelem, size, set->nvertices));
  MICA_CALL_CLEANUP(MICA_MALLOC(set->vertex_key, set->nvertices + 1));
  for (long v = 0; v < set->nvertices; v++) {
    for (int d = 0; d < dim; d++) set->vertex_x[v * dim + d] = mesh->x[nodes[v] * 3 + d];
    set->vertex_key[v] = mesh->node_key ? mesh->node_key[nodes[v]] : nodes[v];
  }
  for (long e = 0; e < mesh->nelements; e++) {
    if (!in_set(ctx, e, phys)) continue;
    for (int a = 0; a < size; a++) {
      const long node = mesh->node[mesh->node_start[e] + a];
      const long *hit = bsearch(&node, nodes, (size_t)set->nvertices, sizeof node, mica_compare_long);
      set->element_vertices[k * size + a] = hit - nodes;
    }
    MICA_CALL_CLEANUP(element_points(ctx, e, k, set, &q));
    k++;
  }
cleanup:
  MICA_FREE(nodes);
  return ierr;
}

static int compare_int(const void *a, const void *b) {
  const int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* The distinct physical tags of the entities of dimension d, ascending; *tags is allocated. */
static int physical_tags(const GmshMesh *mesh, int d, int **tags, int *n) {
  const long total = mesh->entity_phys_start[d] ? mesh->entity_phys_start[d][mesh->nentities[d]] : 0;
  MICA_CALL(MICA_MALLOC(*tags, total));
  if (total) memcpy(*tags, mesh->entity_phys[d], (size_t)total * sizeof **tags);
  qsort(*tags, (size_t)total, sizeof **tags, compare_int);
  *n = 0;
  for (long i = 0; i < total; i++)
    if (*n == 0 || (*tags)[i] != (*tags)[*n - 1]) (*tags)[(*n)++] = (*tags)[i];
  return MICA_SUCCESS;
}

static void physical_name(const GmshMesh *mesh, int dim, int tag, char *name, size_t size) {
  for (int i = 0; i < mesh->nphysicals; i++)
    if (mesh->physicals[i].dim == dim && mesh->physicals[i].tag == tag) {
      snprintf(name, size, "%s", mesh->physicals[i].name);
      return;
    }
  snprintf(name, size, "%d", tag);
}

static int mesh_boundary(const MeshContext *ctx, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS, *tags = NULL, ntags = 0;
  MICA_CALL(physical_tags(ctx->mesh, ctx->dim - 1, &tags, &ntags));
  MICA_CALL_CLEANUP(MICA_CALLOC(disc->sets, ntags));
  disc->nsets = ntags;
  for (int s = 0; s < ntags; s++) {
    char name[64];
    physical_name(ctx->mesh, ctx->dim - 1, tags[s], name, sizeof name);
    MICA_CALL_CLEANUP(build_set(ctx, tags[s], name, &disc->sets[s]));
  }
cleanup:
  MICA_FREE(tags);
  return ierr;
}

/* ---- does the union of the sets cover the boundary once? ---- */

/* Keys of the set elements, one per (element, physical group of dimension dim − 1 holding it); allocated. */
static int held_faces(const MeshContext *ctx, FaceKey **held, long *n) {
  const GmshMesh *mesh = ctx->mesh;
  const int *tags;
  long count = 0;
  for (long e = 0; e < mesh->nelements; e++)
    if (gmsh_element_dim(mesh->type[e]) == ctx->dim - 1)
      count += gmsh_entity_physicals(mesh, mesh->entity_dim[e], mesh->entity_tag[e], &tags);
  MICA_CALL(MICA_MALLOC(*held, count));
  *n = 0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (gmsh_element_dim(mesh->type[e]) != ctx->dim - 1) continue;
    const long groups = gmsh_entity_physicals(mesh, mesh->entity_dim[e], mesh->entity_tag[e], &tags);
    for (long k = 0; k < groups; k++)
      (*held)[(*n)++] = make_key(&mesh->node[mesh->node_start[e]], gmsh_element_nodes(mesh->type[e]), e);
  }
  qsort(*held, (size_t)*n, sizeof **held, compare_face);
  return MICA_SUCCESS;
}

/* Boundary faces (sides of exactly one volume element) held by no set or by several, plus held faces inside
 * the body (sides of two). VCI's boundary sums need 0. Both lists are sorted: one merged pass. */
static int count_uncovered(const MeshContext *ctx, long *uncovered) {
  FaceKey *held = NULL;
  long nheld = 0, h = 0;
  MICA_CALL(held_faces(ctx, &held, &nheld));
  *uncovered = 0;
  for (long i = 0, j; i < ctx->nfaces; i = j) {
    for (j = i + 1; j < ctx->nfaces && compare_face(&ctx->faces[j], &ctx->faces[i]) == 0; j++) continue;
    while (h < nheld && compare_face(&held[h], &ctx->faces[i]) < 0) h++;
    long times = 0;
    for (; h < nheld && compare_face(&held[h], &ctx->faces[i]) == 0; h++) times++;
    double c[3];
    if (ctx->mine) face_centroid(ctx->mesh, &ctx->faces[i], c);
    if (!ctx->mine || ctx->mine(c, ctx->mine_ctx)) *uncovered += j - i == 1 ? times != 1 : times;
  }
  MICA_FREE(held);
  return MICA_SUCCESS;
}

/* ---- the whole mesh ---- */

static int make_rules(const GmshMesh *mesh, int dim, int order, int boundary_order, Rule rules[TYPE_MAX]) {
  for (long e = 0; e < mesh->nelements; e++) {
    const int t = mesh->type[e], edim = gmsh_element_dim(t);
    if ((edim != dim && edim != dim - 1) || rules[t].r) continue;
    MICA_CALL(make_rule(t, edim == dim ? order : boundary_order, &rules[t]));
  }
  return MICA_SUCCESS;
}

/* Does any entity belong to a physical group? */
static int has_groups(const GmshMesh *mesh) {
  for (int d = 0; d < 4; d++)
    if (mesh->entity_phys_start[d] && mesh->entity_phys_start[d][mesh->nentities[d]] > 0) return 1;
  return 0;
}

int geom_mesh_check_dimension(const GmshMesh *mesh) {
  MICA_CHECK(geom_mesh_dimension(mesh) >= 2, MICA_ERR_INPUT, "%s: the mesh has no 2-D or 3-D elements%s", mesh->path,
             has_groups(mesh) ? ": with physical groups defined, Gmsh keeps only the elements of physical groups; "
                                "add one that holds the body, e.g. Physical Surface(\"body\") = {1}; (3-D: Physical "
                                "Volume)"
                              : "");
  return MICA_SUCCESS;
}

int geom_mesh_discretize(const GmshMesh *mesh, int order, int boundary_order, MicaDiscretization *disc) {
  int ierr = MICA_SUCCESS;
  Rule rules[TYPE_MAX] = {{0}};
  FaceKey *faces = NULL;
  long nfaces = 0;
  const int dim = geom_mesh_dimension(mesh);
  MICA_CALL(geom_mesh_check_dimension(mesh));
  disc->dim = dim;
  MICA_CALL_CLEANUP(make_rules(mesh, dim, order, boundary_order, rules));
  MICA_CALL_CLEANUP(mesh_particles(mesh, dim, disc));
  MICA_CALL_CLEANUP(mesh_volume(mesh, dim, rules, disc));
  MICA_CALL_CLEANUP(face_table(mesh, dim, &faces, &nfaces));
  const MeshContext ctx = {mesh, dim, rules, faces, nfaces, NULL, NULL};
  MICA_CALL_CLEANUP(mesh_boundary(&ctx, disc));
  if (mesh->part_dim) disc->boundary_uncovered = mesh->part_uncovered; /* its cut faces are not the body's */
  else MICA_CALL_CLEANUP(count_uncovered(&ctx, &disc->boundary_uncovered));
cleanup:
  free_rules(rules);
  MICA_FREE(faces);
  return ierr;
}

int geom_mesh_faces(const GmshMesh *mesh, int dim, long *uncovered, long *side_of) {
  return geom_mesh_faces_where(mesh, dim, NULL, NULL, uncovered, side_of);
}

int geom_mesh_faces_where(const GmshMesh *mesh, int dim, int (*mine)(const double *, void *), void *mine_ctx,
                          long *uncovered, long *side_of) {
  int ierr = MICA_SUCCESS;
  FaceKey *faces = NULL;
  long nfaces = 0;
  MICA_CALL_CLEANUP(face_table(mesh, dim, &faces, &nfaces));
  const MeshContext ctx = {mesh, dim, NULL, faces, nfaces, mine, mine_ctx};
  if (uncovered) MICA_CALL_CLEANUP(count_uncovered(&ctx, uncovered));
  for (long e = 0; side_of && e < mesh->nelements; e++) {
    side_of[e] = -1;
    if (gmsh_element_dim(mesh->type[e]) != dim - 1) continue;
    const FaceKey key = make_key(&mesh->node[mesh->node_start[e]], gmsh_element_nodes(mesh->type[e]), -1);
    const FaceKey *hit = bsearch(&key, faces, (size_t)nfaces, sizeof key, compare_face);
    if (hit) side_of[e] = hit->element;
  }
cleanup:
  MICA_FREE(faces);
  return ierr;
}
