/* The built-in shapes as maps X(ξ) from the parameter box [0,1]^dim onto the body, their Jacobians, their
 * boundary sets as faces of the parameter box, and the checks of their parameters
 * (docs/theory.md §geometry, "Shape maps"):
 *   box         affine, x_d = lower_d + ξ_d (upper_d − lower_d);
 *   polygon     bilinear through the four vertices (ξ along v0→v1, η along v0→v3);
 *   plate_hole  transfinite, X = (1 − η) H(ξ) + η S(ξ): H on the hole at θ = ξπ/2, S on the outer sides,
 *               each side traversed uniformly, the corner (bx, by) at ξ = 1/2 (orientation-reversing);
 *   annulus     polar, r = r_inner + ξ Δr, θ = theta0 + η Δθ;
 *   cylinder    the elliptical grid map of the square [−1,1]² onto the unit disk, scaled by R, times z = ζ H.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "geom_private.h"

/* ---- small linear algebra ---- */

double geom_det(int dim, const double *j) {
  if (dim == 2) return j[0] * j[3] - j[1] * j[2];
  return j[0] * (j[4] * j[8] - j[5] * j[7]) - j[1] * (j[3] * j[8] - j[5] * j[6]) +
         j[2] * (j[3] * j[7] - j[4] * j[6]);
}

/* Column a of cof(J) = det(J) J^−T. In 3-D it is the cross product of the other two columns of J taken
 * cyclically, ∂X/∂ξ_b × ∂X/∂ξ_c: its length is the area element of the face ξ_a = const. */
void geom_cofactor_column(int dim, const double *j, int a, double *col) {
  if (dim == 2) {
    if (a == 0)
      col[0] = j[3], col[1] = -j[1];
    else
      col[0] = -j[2], col[1] = j[0];
    return;
  }
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  col[0] = j[3 + b] * j[6 + c] - j[6 + b] * j[3 + c];
  col[1] = j[6 + b] * j[c] - j[b] * j[6 + c];
  col[2] = j[b] * j[3 + c] - j[3 + b] * j[c];
}

/* ---- boundary set definitions ---- */

/* A whole face ξ_axis = side. */
static GeomFacePiece whole_face(int axis, int side) {
  GeomFacePiece p = {.axis = axis, .side = side, .lo = {0, 0, 0}, .hi = {1, 1, 1}};
  p.lo[axis] = p.hi[axis] = side;
  return p;
}

static void add_set(GeomMap *map, const char *name, int npieces, const GeomFacePiece *pieces) {
  GeomSetSpec *s = &map->sets[map->nsets++];
  snprintf(s->name, sizeof s->name, "%s", name);
  s->npieces = npieces;
  for (int i = 0; i < npieces; i++) s->pieces[i] = pieces[i];
}

static void add_face_set(GeomMap *map, const char *name, int axis, int side) {
  const GeomFacePiece p = whole_face(axis, side);
  add_set(map, name, 1, &p);
}

/* left/right (ξ = 0, 1), bottom/top (η = 0, 1), back/front (ζ = 0, 1): box and polygon. */
static void add_box_sets(GeomMap *map) {
  static const char *names[3][2] = {{"left", "right"}, {"bottom", "top"}, {"back", "front"}};
  for (int axis = 0; axis < map->dim; axis++)
    for (int side = 0; side < 2; side++) add_face_set(map, names[axis][side], axis, side);
}

/* ---- box ---- */

static int box_init(GeomMap *map) {
  const MicaShapeSpec *s = &map->shape;
  MICA_CHECK(s->dim == 2 || s->dim == 3, MICA_ERR_INPUT, "box: the dimension must be 2 or 3 (got %d)",
             s->dim);
  map->dim = s->dim;
  for (int d = 0; d < s->dim; d++)
    MICA_CHECK(s->upper[d] > s->lower[d] && isfinite(s->upper[d] - s->lower[d]), MICA_ERR_INPUT,
               "box: upper[%d] = %g must exceed lower[%d] = %g", d, s->upper[d], d, s->lower[d]);
  add_box_sets(map);
  return MICA_SUCCESS;
}

static void box_eval(const MicaShapeSpec *s, int dim, const double *xi, double *x, double *jac) {
  for (int d = 0; d < dim; d++) x[d] = s->lower[d] + xi[d] * (s->upper[d] - s->lower[d]);
  if (!jac) return;
  for (int i = 0; i < dim; i++)
    for (int j = 0; j < dim; j++) jac[i * dim + j] = i == j ? s->upper[i] - s->lower[i] : 0.0;
}

/* ---- polygon (bilinear quadrilateral) ---- */

static double cross2(const double *o, const double *a, const double *b) {
  return (a[0] - o[0]) * (b[1] - a[1]) - (a[1] - o[1]) * (b[0] - a[0]);
}

/* Convex and counterclockwise: every turn v_k → v_k+1 → v_k+2 is strictly to the left. Then the bilinear
 * map has a positive Jacobian everywhere: det J is affine in ξ and in η (no ξη term), and at each corner
 * it equals that corner's turn. */
static int polygon_init(GeomMap *map) {
  const double(*v)[2] = (const double(*)[2])map->shape.vertices;
  map->dim = 2;
  for (int k = 0; k < 4; k++) {
    const double *o = v[k], *a = v[(k + 1) % 4], *b = v[(k + 2) % 4];
    const double la = hypot(a[0] - o[0], a[1] - o[1]), lb = hypot(b[0] - a[0], b[1] - a[1]);
    const double turn = cross2(o, a, b);
    MICA_CHECK(isfinite(turn) && turn > 1e-12 * la * lb && la > 0 && lb > 0, MICA_ERR_INPUT,
               "polygon: the vertices (%g, %g), (%g, %g), (%g, %g), (%g, %g) are not a convex quadrilateral "
               "in counterclockwise order (turn at vertex %d)",
               v[0][0], v[0][1], v[1][0], v[1][1], v[2][0], v[2][1], v[3][0], v[3][1], (k + 1) % 4);
  }
  add_box_sets(map);
  return MICA_SUCCESS;
}

static void polygon_eval(const MicaShapeSpec *s, const double *xi, double *x, double *jac) {
  const double(*v)[2] = (const double(*)[2])s->vertices;
  const double u = xi[0], e = xi[1];
  const double n[4] = {(1 - u) * (1 - e), u * (1 - e), u * e, (1 - u) * e};
  const double du[4] = {-(1 - e), 1 - e, e, -e}, de[4] = {-(1 - u), -u, u, 1 - u};
  for (int i = 0; i < 2; i++) {
    x[i] = 0.0;
    for (int k = 0; k < 4; k++) x[i] += n[k] * v[k][i];
    if (!jac) continue;
    jac[2 * i] = jac[2 * i + 1] = 0.0;
    for (int k = 0; k < 4; k++) {
      jac[2 * i] += du[k] * v[k][i];
      jac[2 * i + 1] += de[k] * v[k][i];
    }
  }
}

/* ---- quarter plate with a hole ---- */

static int plate_init(GeomMap *map) {
  const MicaShapeSpec *s = &map->shape;
  const double a = s->hole_radius, bx = s->plate_size[0], by = s->plate_size[1];
  map->dim = 2;
  MICA_CHECK(bx > 0 && by > 0 && isfinite(bx) && isfinite(by), MICA_ERR_INPUT,
             "plate_hole: the plate size (%g, %g) must be positive", bx, by);
  MICA_CHECK(a > 0 && a < fmin(bx, by), MICA_ERR_INPUT,
             "plate_hole: the hole radius %g must be positive and smaller than the plate (%g × %g)", a, bx,
             by);
  const GeomFacePiece right = {.axis = 1, .side = 1, .lo = {0, 1, 0}, .hi = {0.5, 1, 0}};
  const GeomFacePiece top = {.axis = 1, .side = 1, .lo = {0.5, 1, 0}, .hi = {1, 1, 0}};
  add_face_set(map, "hole", 1, 0);
  add_set(map, "right", 1, &right);
  add_set(map, "top", 1, &top);
  add_face_set(map, "bottom", 0, 0);
  add_face_set(map, "left", 0, 1);
  map->nkinks[0] = 1;
  map->kinks[0][0] = 0.5; /* the corner (bx, by) */
  return MICA_SUCCESS;
}

/* The outer boundary S(ξ) and S'(ξ): up the right side for ξ ≤ 1/2, then leftward along the top. */
static void plate_outer(double bx, double by, double xi, double s[2], double ds[2]) {
  if (xi <= 0.5) {
    s[0] = bx, s[1] = 2.0 * xi * by;
    ds[0] = 0.0, ds[1] = 2.0 * by;
  } else {
    s[0] = (2.0 - 2.0 * xi) * bx, s[1] = by;
    ds[0] = -2.0 * bx, ds[1] = 0.0;
  }
}

static void plate_eval(const MicaShapeSpec *s, const double *xi, double *x, double *jac) {
  const double a = s->hole_radius, e = xi[1];
  /* cos θ as sin(π/2 − θ): both ends of the arc are then exact, (a, 0) and (0, a) */
  const double h[2] = {a * sin(0.5 * GEOM_PI * (1.0 - xi[0])), a * sin(0.5 * GEOM_PI * xi[0])};
  const double dh[2] = {-0.5 * GEOM_PI * h[1], 0.5 * GEOM_PI * h[0]};
  double o[2], dout[2];
  plate_outer(s->plate_size[0], s->plate_size[1], xi[0], o, dout);
  for (int i = 0; i < 2; i++) {
    x[i] = (1.0 - e) * h[i] + e * o[i];
    if (jac) {
      jac[2 * i] = (1.0 - e) * dh[i] + e * dout[i];
      jac[2 * i + 1] = o[i] - h[i];
    }
  }
}

/* ---- annulus sector ---- */

static int annulus_init(GeomMap *map) {
  const MicaShapeSpec *s = &map->shape;
  map->dim = 2;
  MICA_CHECK(s->r_inner > 0 && s->r_outer > s->r_inner && isfinite(s->r_outer), MICA_ERR_INPUT,
             "annulus: need 0 < r_inner < r_outer (got r_inner = %g, r_outer = %g)", s->r_inner, s->r_outer);
  const double span = s->theta1 - s->theta0;
  MICA_CHECK(span > 0 && span < 2.0 * GEOM_PI, MICA_ERR_INPUT,
             "annulus: need 0 < theta1 − theta0 < 2π (got %g rad); a full ring would put particles on top "
             "of each other at the seam",
             span);
  add_face_set(map, "inner", 0, 0);
  add_face_set(map, "outer", 0, 1);
  add_face_set(map, "start", 1, 0);
  add_face_set(map, "end", 1, 1);
  return MICA_SUCCESS;
}

static void annulus_eval(const MicaShapeSpec *s, const double *xi, double *x, double *jac) {
  const double dr = s->r_outer - s->r_inner, dth = s->theta1 - s->theta0;
  const double r = s->r_inner + xi[0] * dr, th = s->theta0 + xi[1] * dth;
  const double c = cos(th), sn = sin(th);
  x[0] = r * c, x[1] = r * sn;
  if (!jac) return;
  jac[0] = dr * c, jac[1] = -r * dth * sn;
  jac[2] = dr * sn, jac[3] = r * dth * c;
}

/* ---- cylinder ---- */

static int cylinder_init(GeomMap *map) {
  const MicaShapeSpec *s = &map->shape;
  map->dim = 3;
  MICA_CHECK(s->radius > 0 && s->height > 0 && isfinite(s->radius) && isfinite(s->height), MICA_ERR_INPUT,
             "cylinder: radius (%g) and height (%g) must be positive", s->radius, s->height);
  const GeomFacePiece side[4] = {whole_face(0, 0), whole_face(0, 1), whole_face(1, 0), whole_face(1, 1)};
  add_set(map, "side", 4, side);
  add_face_set(map, "bottom", 2, 0);
  add_face_set(map, "top", 2, 1);
  return MICA_SUCCESS;
}

/* (u, v) = (2ξ − 1, 2η − 1) ∈ [−1,1]² → R (u √(1 − v²/2), v √(1 − u²/2)): the square's sides go onto
 * the circle (x² + y² = u² + v² − u²v² = 1 when |u| = 1 or |v| = 1). */
static void cylinder_eval(const MicaShapeSpec *s, const double *xi, double *x, double *jac) {
  const double R = s->radius, u = 2.0 * xi[0] - 1.0, v = 2.0 * xi[1] - 1.0;
  const double su = sqrt(1.0 - 0.5 * u * u), sv = sqrt(1.0 - 0.5 * v * v);
  x[0] = R * u * sv, x[1] = R * v * su, x[2] = s->height * xi[2];
  if (!jac) return;
  jac[0] = 2.0 * R * sv, jac[1] = -R * u * v / sv, jac[2] = 0.0;
  jac[3] = -R * u * v / su, jac[4] = 2.0 * R * su, jac[5] = 0.0;
  jac[6] = 0.0, jac[7] = 0.0, jac[8] = s->height;
}

/* ---- dispatch ---- */

void geom_map_eval(const GeomMap *map, const double *xi, double *x, double *jac) {
  const MicaShapeSpec *s = &map->shape;
  switch (s->kind) {
  case MICA_SHAPE_BOX: box_eval(s, map->dim, xi, x, jac); break;
  case MICA_SHAPE_POLYGON: polygon_eval(s, xi, x, jac); break;
  case MICA_SHAPE_PLATE_HOLE: plate_eval(s, xi, x, jac); break;
  case MICA_SHAPE_ANNULUS: annulus_eval(s, xi, x, jac); break;
  case MICA_SHAPE_CYLINDER: cylinder_eval(s, xi, x, jac); break;
  case MICA_SHAPE_GMSH: break;
  }
}

int geom_map_init(const MicaShapeSpec *shape, GeomMap *map) {
  memset(map, 0, sizeof *map);
  map->shape = *shape;
  map->shape.mesh_path = NULL;
  switch (shape->kind) {
  case MICA_SHAPE_BOX: MICA_CALL(box_init(map)); break;
  case MICA_SHAPE_POLYGON: MICA_CALL(polygon_init(map)); break;
  case MICA_SHAPE_PLATE_HOLE: MICA_CALL(plate_init(map)); break;
  case MICA_SHAPE_ANNULUS: MICA_CALL(annulus_init(map)); break;
  case MICA_SHAPE_CYLINDER: MICA_CALL(cylinder_init(map)); break;
  default: MICA_ERROR(MICA_ERR_ARGUMENT, "geom_map_init: shape kind %d has no map", (int)shape->kind);
  }
  /* the orientation at the center of the parameter box; cells check every point against it */
  const double center[3] = {0.5, 0.5, 0.5};
  double x[3], jac[9];
  geom_map_eval(map, center, x, jac);
  map->orientation = geom_det(map->dim, jac) > 0 ? 1.0 : -1.0;
  return MICA_SUCCESS;
}
