/* MicaBody: is a point in the body? Built-in shapes answer from their exact geometry (box, convex
 * quadrilateral, quarter plate minus the hole's disk, annulus sector, cylinder); a Gmsh mesh from its volume
 * elements (triangles and tetrahedra directly, quadrilaterals as two triangles, hexahedra as the six
 * tetrahedra around the diagonal from node 0 to node 6 — exact for planar faces). Every test is a signed
 * distance against tol, so points on the boundary are inside whatever round-off their coordinates carry
 * (docs/theory.md §geometry, "Inside the body"). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "geom_private.h"

struct MicaBody {
  MicaShapeSpec shape;      /* a copy of the parameters (mesh_path points into path) */
  char path[512];           /* a Gmsh mesh's file */
  int dim;
  double lower[3], upper[3]; /* the bounding box */
  double tol;               /* MICA_BODY_TOLERANCE × the box's diagonal */
  GmshMesh mesh;            /* a Gmsh mesh as read (zeroed for built-in shapes) */
  const GmshMesh *elements; /* the mesh whose elements make the body: &mesh, or a rank's part (not owned) */
  int mesh_dim;             /* the dimension of its volume elements */
};

/* ---- signed distances ---- */

/* The distance of x from the line through p and q, positive on the side where r lies (−INFINITY if p = q). */
static double side_distance2(const double *p, const double *q, const double *r, const double *x) {
  const double ex = q[0] - p[0], ey = q[1] - p[1], len = hypot(ex, ey);
  if (!(len > 0)) return -INFINITY;
  const double sr = ex * (r[1] - p[1]) - ey * (r[0] - p[0]), sx = ex * (x[1] - p[1]) - ey * (x[0] - p[0]);
  return (sr >= 0 ? sx : -sx) / len;
}

/* The distance of x from the plane through p, q, r, positive on the side where o lies. */
static double side_distance3(const double *p, const double *q, const double *r, const double *o, const double *x) {
  const double a[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, b[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
  const double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (!(len > 0)) return -INFINITY;
  double so = 0, sx = 0;
  for (int d = 0; d < 3; d++) so += n[d] * (o[d] - p[d]), sx += n[d] * (x[d] - p[d]);
  return (so >= 0 ? sx : -sx) / len;
}

static int in_triangle(const double *a, const double *b, const double *c, const double *x, double tol) {
  return side_distance2(a, b, c, x) >= -tol && side_distance2(b, c, a, x) >= -tol &&
         side_distance2(c, a, b, x) >= -tol;
}

static int in_tetrahedron(const double *a, const double *b, const double *c, const double *d, const double *x,
                          double tol) {
  return side_distance3(a, b, c, d, x) >= -tol && side_distance3(a, b, d, c, x) >= -tol &&
         side_distance3(a, c, d, b, x) >= -tol && side_distance3(b, c, d, a, x) >= -tol;
}

/* The distance of x from the segment p–q (2-D). */
static double segment_distance(const double *p, const double *q, const double *x) {
  const double ex = q[0] - p[0], ey = q[1] - p[1], l2 = ex * ex + ey * ey;
  double t = l2 > 0 ? ((x[0] - p[0]) * ex + (x[1] - p[1]) * ey) / l2 : 0;
  t = fmin(1.0, fmax(0.0, t));
  return hypot(x[0] - p[0] - t * ex, x[1] - p[1] - t * ey);
}

/* ---- built-in shapes ---- */

/* (r cos θ, r sin θ), with the round-off of cos(π/2) and the like (6e-17 r) set to 0: exact axes for bounds. */
static void polar(double r, double th, double p[2]) {
  p[0] = r * cos(th), p[1] = r * sin(th);
  for (int d = 0; d < 2; d++)
    if (fabs(p[d]) < 1e-15 * r) p[d] = 0;
}

static int in_box(const MicaBody *b, const double *x) {
  for (int d = 0; d < b->dim; d++)
    if (x[d] < b->shape.lower[d] - b->tol || x[d] > b->shape.upper[d] + b->tol) return 0;
  return 1;
}

/* Convex and counterclockwise (the shape map checked it): on the left of every edge. */
static int in_polygon(const MicaBody *b, const double *x) {
  const double(*v)[2] = (const double(*)[2])b->shape.vertices;
  for (int k = 0; k < 4; k++)
    if (side_distance2(v[k], v[(k + 1) % 4], v[(k + 2) % 4], x) < -b->tol) return 0;
  return 1;
}

static int in_plate(const MicaBody *b, const double *x) {
  const MicaShapeSpec *s = &b->shape;
  return x[0] >= -b->tol && x[1] >= -b->tol && x[0] <= s->plate_size[0] + b->tol &&
         x[1] <= s->plate_size[1] + b->tol && hypot(x[0], x[1]) >= s->hole_radius - b->tol;
}

/* Within the radii and the angles, or within tol of one of the two straight edges. */
static int in_annulus(const MicaBody *b, const double *x) {
  const MicaShapeSpec *s = &b->shape;
  const double r = hypot(x[0], x[1]);
  if (r < s->r_inner - b->tol || r > s->r_outer + b->tol) return 0;
  double turn = fmod(atan2(x[1], x[0]) - s->theta0, 2.0 * GEOM_PI);
  if (turn < 0) turn += 2.0 * GEOM_PI;
  if (turn <= s->theta1 - s->theta0) return 1;
  for (int e = 0; e < 2; e++) {
    double p[2], q[2];
    polar(s->r_inner, e ? s->theta1 : s->theta0, p);
    polar(s->r_outer, e ? s->theta1 : s->theta0, q);
    if (segment_distance(p, q, x) <= b->tol) return 1;
  }
  return 0;
}

static int in_cylinder(const MicaBody *b, const double *x) {
  return hypot(x[0], x[1]) <= b->shape.radius + b->tol && x[2] >= -b->tol && x[2] <= b->shape.height + b->tol;
}

/* ---- Gmsh meshes ---- */

static const double *node_x(const GmshMesh *m, long e, int k) { return &m->x[m->node[m->node_start[e] + k] * 3]; }

/* Inside the bounding box of element e, widened by tol. */
static int near_element(const GmshMesh *m, long e, int dim, const double *x, double tol) {
  const int n = (int)(m->node_start[e + 1] - m->node_start[e]);
  for (int d = 0; d < dim; d++) {
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < n; k++) lo = fmin(lo, node_x(m, e, k)[d]), hi = fmax(hi, node_x(m, e, k)[d]);
    if (x[d] < lo - tol || x[d] > hi + tol) return 0;
  }
  return 1;
}

static int in_element(const GmshMesh *m, long e, const double *x, double tol) {
  /* the hexahedron's six tetrahedra: 0 and 6 with each pair of neighbours on the cycle 1 2 3 7 4 5 */
  static const int ring[6] = {1, 2, 3, 7, 4, 5};
  const double *v[8];
  const int n = (int)(m->node_start[e + 1] - m->node_start[e]);
  for (int k = 0; k < n && k < 8; k++) v[k] = node_x(m, e, k);
  switch (m->type[e]) {
  case GMSH_TRI3: return in_triangle(v[0], v[1], v[2], x, tol);
  case GMSH_QUAD4: return in_triangle(v[0], v[1], v[2], x, tol) || in_triangle(v[0], v[2], v[3], x, tol);
  case GMSH_TET4: return in_tetrahedron(v[0], v[1], v[2], v[3], x, tol);
  case GMSH_HEX8:
    for (int k = 0; k < 6; k++)
      if (in_tetrahedron(v[0], v[ring[k]], v[ring[(k + 1) % 6]], v[6], x, tol)) return 1;
    return 0;
  default: return 0;
  }
}

static int in_mesh(const MicaBody *b, const double *x) {
  const GmshMesh *m = b->elements;
  double x3[3] = {x[0], x[1], b->dim == 3 ? x[2] : 0.0};
  for (long e = 0; e < m->nelements; e++)
    if (gmsh_element_dim(m->type[e]) == b->mesh_dim && near_element(m, e, b->dim, x3, b->tol) &&
        in_element(m, e, x3, b->tol))
      return 1;
  return 0;
}

/* ---- bounds ---- */

static void widen(MicaBody *b, const double *x) {
  for (int d = 0; d < b->dim; d++) b->lower[d] = fmin(b->lower[d], x[d]), b->upper[d] = fmax(b->upper[d], x[d]);
}

/* The annulus sector's box: the four corners and the outer arc wherever it crosses an axis. */
static void annulus_bounds(MicaBody *b) {
  const MicaShapeSpec *s = &b->shape;
  for (int e = 0; e < 2; e++) {
    double p[2], q[2];
    polar(s->r_inner, e ? s->theta1 : s->theta0, p);
    polar(s->r_outer, e ? s->theta1 : s->theta0, q);
    widen(b, p), widen(b, q);
  }
  for (double k = ceil(s->theta0 / (0.5 * GEOM_PI)); k * 0.5 * GEOM_PI <= s->theta1; k++) {
    double p[2];
    polar(s->r_outer, k * 0.5 * GEOM_PI, p);
    widen(b, p);
  }
}

static void mesh_bounds(MicaBody *b) {
  const GmshMesh *m = b->elements;
  for (long e = 0; e < m->nelements; e++)
    if (gmsh_element_dim(m->type[e]) == b->mesh_dim)
      for (int k = 0; k < (int)(m->node_start[e + 1] - m->node_start[e]); k++) widen(b, node_x(m, e, k));
}

static void shape_bounds(MicaBody *b) {
  const MicaShapeSpec *s = &b->shape;
  switch (s->kind) {
  case MICA_SHAPE_BOX: widen(b, s->lower), widen(b, s->upper); break;
  case MICA_SHAPE_POLYGON:
    for (int k = 0; k < 4; k++) widen(b, s->vertices[k]);
    break;
  case MICA_SHAPE_PLATE_HOLE: {
    const double o[2] = {0, 0};
    widen(b, o), widen(b, s->plate_size);
    break;
  }
  case MICA_SHAPE_ANNULUS: annulus_bounds(b); break;
  case MICA_SHAPE_CYLINDER: {
    const double lo[3] = {-s->radius, -s->radius, 0}, hi[3] = {s->radius, s->radius, s->height};
    widen(b, lo), widen(b, hi);
    break;
  }
  case MICA_SHAPE_GMSH: mesh_bounds(b); break;
  }
}

/* ---- the object ---- */

static int read_mesh(MicaBody *b) {
  MICA_CHECK(b->shape.mesh_path && b->shape.mesh_path[0], MICA_ERR_INPUT, "gmsh: no mesh file given");
  snprintf(b->path, sizeof b->path, "%s", b->shape.mesh_path);
  b->shape.mesh_path = b->path;
  MICA_CALL(gmsh_read(b->path, b->shape.mesh_size_factor, &b->mesh));
  b->elements = &b->mesh;
  for (long e = 0; e < b->mesh.nelements; e++)
    if (gmsh_element_dim(b->mesh.type[e]) > b->mesh_dim) b->mesh_dim = gmsh_element_dim(b->mesh.type[e]);
  MICA_CHECK(b->mesh_dim == 2 || b->mesh_dim == 3, MICA_ERR_INPUT, "%s: the mesh has no 2-D or 3-D elements",
             b->path);
  b->dim = b->mesh_dim;
  return MICA_SUCCESS;
}

/* The tolerance from the bounding box. */
static void set_tolerance(MicaBody *b) {
  double diagonal = 0;
  for (int d = 0; d < b->dim; d++) diagonal += (b->upper[d] - b->lower[d]) * (b->upper[d] - b->lower[d]);
  b->tol = MICA_BODY_TOLERANCE * sqrt(diagonal);
}

static int create_body(const MicaShapeSpec *shape, const MicaMesh *part, MicaBody **body) {
  int ierr = MICA_SUCCESS;
  MICA_CHECK(shape && body, MICA_ERR_ARGUMENT, "mica_body_create: NULL argument");
  *body = NULL;
  MicaBody *b = NULL;
  MICA_CALL(MICA_CALLOC(b, 1));
  b->shape = *shape;
  if (part) {
    snprintf(b->path, sizeof b->path, "%s", shape->mesh_path ? shape->mesh_path : "");
    b->shape.mesh_path = b->path;
    b->elements = geom_mesh_of(part);
    b->dim = b->mesh_dim = mica_mesh_dim(part);
  } else if (shape->kind == MICA_SHAPE_GMSH) {
    MICA_CALL_CLEANUP(read_mesh(b));
  } else {
    GeomMap map; /* the shape's own checks of its parameters (e.g. a convex, counterclockwise polygon) */
    MICA_CALL_CLEANUP(geom_map_init(shape, &map));
    b->dim = map.dim;
  }
  for (int d = 0; d < 3; d++) b->lower[d] = d < b->dim ? INFINITY : 0, b->upper[d] = d < b->dim ? -INFINITY : 0;
  shape_bounds(b);
  set_tolerance(b);
  *body = b;
  return MICA_SUCCESS;
cleanup:
  mica_body_destroy(&b);
  return ierr;
}

int mica_body_create(const MicaShapeSpec *shape, MicaBody **body) { return create_body(shape, NULL, body); }

int mica_body_create_part(const MicaShapeSpec *shape, const MicaMesh *part, MicaBody **body) {
  MICA_CHECK(shape && shape->kind == MICA_SHAPE_GMSH && part, MICA_ERR_ARGUMENT,
             "mica_body_create_part: a Gmsh shape and its part");
  return create_body(shape, part, body);
}

void mica_body_set_bounds(MicaBody *body, const double lower[3], const double upper[3]) {
  memcpy(body->lower, lower, sizeof body->lower);
  memcpy(body->upper, upper, sizeof body->upper);
  set_tolerance(body);
}

int mica_body_destroy(MicaBody **body) {
  if (!body || !*body) return MICA_SUCCESS;
  gmsh_free(&(*body)->mesh);
  MICA_FREE(*body);
  return MICA_SUCCESS;
}

int mica_body_dim(const MicaBody *body) { return body->dim; }

void mica_body_bounds(const MicaBody *body, double lower[3], double upper[3]) {
  memcpy(lower, body->lower, sizeof body->lower);
  memcpy(upper, body->upper, sizeof body->upper);
}

int mica_body_contains(const MicaBody *body, const double *x) {
  switch (body->shape.kind) {
  case MICA_SHAPE_BOX: return in_box(body, x);
  case MICA_SHAPE_POLYGON: return in_polygon(body, x);
  case MICA_SHAPE_PLATE_HOLE: return in_plate(body, x);
  case MICA_SHAPE_ANNULUS: return in_annulus(body, x);
  case MICA_SHAPE_CYLINDER: return in_cylinder(body, x);
  case MICA_SHAPE_GMSH: return in_mesh(body, x);
  }
  return 0;
}

void mica_body_describe(const MicaBody *body, char *buf, int size) {
  const MicaShapeSpec *s = &body->shape;
  switch (s->kind) {
  case MICA_SHAPE_BOX: snprintf(buf, (size_t)size, "the box"); break;
  case MICA_SHAPE_POLYGON: snprintf(buf, (size_t)size, "the quadrilateral"); break;
  case MICA_SHAPE_PLATE_HOLE:
    snprintf(buf, (size_t)size, "the quarter plate with a hole of radius %g", s->hole_radius);
    break;
  case MICA_SHAPE_ANNULUS:
    snprintf(buf, (size_t)size, "the annulus sector %g <= r <= %g, %g <= theta <= %g degrees", s->r_inner, s->r_outer,
             s->theta0 * 180 / GEOM_PI, s->theta1 * 180 / GEOM_PI);
    break;
  case MICA_SHAPE_CYLINDER:
    snprintf(buf, (size_t)size, "the cylinder of radius %g and height %g", s->radius, s->height);
    break;
  case MICA_SHAPE_GMSH: snprintf(buf, (size_t)size, "the elements of %s", body->path); break;
  }
}
