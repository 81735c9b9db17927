/* Field output for ParaView: VTU files (VTK XML unstructured grid, one vertex cell per point, binary
 * appended data, base64-free raw encoding) and PVD collections of load steps. Written atomically. */
#ifndef MICA_VTK_H
#define MICA_VTK_H

#include "mica/error.h"

typedef struct MicaVtkField {
  const char *name;   /* "displacement", "stress", ... */
  int ncomp;          /* 1 (scalar), 3 (vector; 2-D data padded with 0), 9 (tensor, row-major 3×3) */
  const double *data; /* [npoints * ncomp] */
} MicaVtkField;

/* Points x[n*dim] (dim 2 or 3; 2-D points get z = 0) with point data. Non-finite values are refused
 * (MICA_ERR_NUMERIC naming the field): no NaN in the output. */
int mica_vtu_write(const char *path, int dim, long n, const double *x, int nfields, const MicaVtkField *fields);

/* A PVD collection: files[i] (relative to the PVD's directory) at times[i]. */
int mica_pvd_write(const char *path, int nsteps, const double *times, const char *const *files);

#endif
