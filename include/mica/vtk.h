/* Field output for ParaView: VTU files (VTK XML unstructured grid, binary appended data, base64-free raw
 * encoding) of points with vertex cells (a particle cloud) or with cells that list shared points (a mesh), and
 * PVD collections of load steps, one or more series (parts) per step. Written atomically. */
#ifndef MICA_VTK_H
#define MICA_VTK_H

#include "mica/error.h"

typedef struct MicaVtkField {
  const char *name;   /* "displacement", "stress", ... */
  int ncomp;          /* 1 (scalar), 3 (vector; 2-D data padded with 0), 9 (tensor, row-major 3×3) */
  const double *data; /* [npoints * ncomp] */
  const char *const *components; /* NULL, or ncomp names ("x", "r", "rtheta", ...) written as VTK's
                                    ComponentName attributes, which ParaView shows in its menus */
} MicaVtkField;

/* Cells on the points: cell c lists conn[offsets[c] .. offsets[c+1]) (offsets[0] = 0) and has VTK cell type
 * type[c]; the node count must be the type's (1 vertex, 3 triangle, 4 quad or tetra, 8 hexahedron, 6, 8, 10,
 * 20 quadratic triangle, quad, tetra, hexahedron, 9 biquadratic quad, 27 triquadratic hexahedron). */
typedef struct MicaVtkCells {
  long n;
  const long *offsets;
  const long *conn;
  const unsigned char *type;
} MicaVtkCells;

/* Points x[n*dim] (dim 2 or 3; 2-D points get z = 0) with point data, each point a vertex cell. Non-finite
 * values are refused (MICA_ERR_NUMERIC naming the field): no NaN in the output. */
int mica_vtu_write(const char *path, int dim, long n, const double *x, int nfields, const MicaVtkField *fields);
/* The same with the given cells; a cell with another node count than its type's, an unknown type or a point
 * index outside [0, n) is MICA_ERR_ARGUMENT, and nothing is written. */
int mica_vtu_write_cells(const char *path, int dim, long n, const double *x, const MicaVtkCells *cells, int nfields,
                         const MicaVtkField *fields);

/* A parallel VTU file (.pvtu): the pieces (VTU files, relative to its directory) that together make one data
 * set, each written by one rank with the point data `fields` declares (names, components; data unused). */
int mica_pvtu_write(const char *path, int nfields, const MicaVtkField *fields, int npieces,
                    const char *const *pieces);

/* A PVD collection: files[i] (relative to the PVD's directory) at times[i]. */
int mica_pvd_write(const char *path, int nsteps, const double *times, const char *const *files);
/* A PVD collection of nparts series: at times[s], files[s*nparts + p] is part p, named names[p] (names may be
 * NULL). ParaView reads the parts of a step as the blocks of one multiblock data set. */
int mica_pvd_write_parts(const char *path, int nsteps, const double *times, int nparts, const char *const *names,
                         const char *const *files);

#endif
