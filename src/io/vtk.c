/* VTU and PVD files for ParaView (vtk.h).
 *
 * A VTU file is VTK's XML UnstructuredGrid with every array in one raw <AppendedData> section: after its
 * '_' marker each array is a UInt64 byte count followed by the bytes, and each DataArray element names
 * its block by offset (bytes from the first byte after '_'). Raw binary keeps full double precision and
 * writes at disk speed, with no base64 or zlib. Every point is a VTK_VERTEX cell, so ParaView can show the
 * particle cloud with any filter. The data are written in the host's byte order, which the header states.
 * Values are checked for finiteness before anything is written, and the file goes through files.h, so a
 * refused or failed write leaves no file.
 */
#include "mica/vtk.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mica/files.h"

enum { VTK_VERTEX = 1, CHUNK = 4096 /* doubles or longs staged per fwrite */ };

/* ---- Checks ------------------------------------------------------------------------------------------- */

static int check_finite(const char *what, const double *data, long count) {
  for (long k = 0; k < count; k++)
    MICA_CHECK(isfinite(data[k]), MICA_ERR_NUMERIC, "VTU output: '%s' holds a non-finite value (%g at index %ld)",
               what, data[k], k);
  return MICA_SUCCESS;
}

static int check_vtu_arguments(const char *path, int dim, long n, const double *x, int nfields,
                               const MicaVtkField *fields) {
  MICA_CHECK(path && (dim == 2 || dim == 3) && n >= 0 && (n == 0 || x) && nfields >= 0 && (nfields == 0 || fields),
             MICA_ERR_ARGUMENT, "mica_vtu_write: bad arguments (dim %d, n %ld, nfields %d)", dim, n, nfields);
  MICA_CALL(check_finite("points", x, n * dim));
  for (int f = 0; f < nfields; f++) {
    MICA_CHECK(fields[f].name && fields[f].ncomp >= 1 && (n == 0 || fields[f].data), MICA_ERR_ARGUMENT,
               "mica_vtu_write: field %d has no name, components or data", f);
    MICA_CALL(check_finite(fields[f].name, fields[f].data, n * fields[f].ncomp));
  }
  return MICA_SUCCESS;
}

/* ---- XML text ----------------------------------------------------------------------------------------- */

/* An attribute value with XML's special characters escaped. */
static void write_escaped(FILE *fp, const char *text) {
  for (const char *c = text; *c; c++) {
    switch (*c) {
    case '&': fputs("&amp;", fp); break;
    case '<': fputs("&lt;", fp); break;
    case '>': fputs("&gt;", fp); break;
    case '"': fputs("&quot;", fp); break;
    default: fputc(*c, fp);
    }
  }
}

static const char *host_byte_order(void) {
  const uint16_t probe = 1;
  return *(const unsigned char *)&probe == 1 ? "LittleEndian" : "BigEndian";
}

/* The DataArray element of one appended block; returns the offset of the block after it. */
static uint64_t write_array_element(FILE *fp, const char *indent, const char *type, const char *name, int ncomp,
                                    uint64_t offset, uint64_t bytes) {
  fprintf(fp, "%s<DataArray type=\"%s\"", indent, type);
  if (name) {
    fputs(" Name=\"", fp);
    write_escaped(fp, name);
    fputc('"', fp);
  }
  if (ncomp > 0) fprintf(fp, " NumberOfComponents=\"%d\"", ncomp);
  fprintf(fp, " format=\"appended\" offset=\"%llu\"/>\n", (unsigned long long)offset);
  return offset + sizeof(uint64_t) + bytes;
}

/* Piece header: point data, points, cells, with the blocks in the order they are appended below. */
static void write_vtu_header(FILE *fp, long n, int nfields, const MicaVtkField *fields) {
  const uint64_t un = (uint64_t)n;
  uint64_t offset = 0;
  fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"%s\" "
              "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"%ld\" NumberOfCells=\"%ld\">\n"
              "      <PointData>\n", host_byte_order(), n, n);
  for (int f = 0; f < nfields; f++)
    offset = write_array_element(fp, "        ", "Float64", fields[f].name, fields[f].ncomp, offset,
                                 un * (uint64_t)fields[f].ncomp * sizeof(double));
  fputs("      </PointData>\n      <Points>\n", fp);
  offset = write_array_element(fp, "        ", "Float64", NULL, 3, offset, un * 3 * sizeof(double));
  fputs("      </Points>\n      <Cells>\n", fp);
  offset = write_array_element(fp, "        ", "Int64", "connectivity", 0, offset, un * sizeof(int64_t));
  offset = write_array_element(fp, "        ", "Int64", "offsets", 0, offset, un * sizeof(int64_t));
  write_array_element(fp, "        ", "UInt8", "types", 0, offset, un);
  fputs("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _", fp);
}

/* ---- Appended blocks ---------------------------------------------------------------------------------- */

static void write_block_size(FILE *fp, uint64_t bytes) { fwrite(&bytes, sizeof bytes, 1, fp); }

static void write_field_block(FILE *fp, long n, const MicaVtkField *field) {
  size_t count = (size_t)n * (size_t)field->ncomp;
  write_block_size(fp, count * sizeof(double));
  if (count > 0) fwrite(field->data, sizeof(double), count, fp);
}

/* Points padded to 3 coordinates, staged through a buffer (no copy of the whole array). */
static void write_points_block(FILE *fp, int dim, long n, const double *x) {
  double staged[3 * (CHUNK / 3)];
  write_block_size(fp, (uint64_t)n * 3 * sizeof(double));
  for (long first = 0; first < n; first += CHUNK / 3) {
    long count = n - first < CHUNK / 3 ? n - first : CHUNK / 3;
    for (long i = 0; i < count; i++)
      for (int d = 0; d < 3; d++) staged[3 * i + d] = d < dim ? x[(first + i) * dim + d] : 0.0;
    fwrite(staged, sizeof(double), (size_t)(3 * count), fp);
  }
}

/* Vertex cells: point i is cell i, so connectivity is 0..n-1 and offsets 1..n (shift = 0 or 1). */
static void write_sequence_block(FILE *fp, long n, int64_t shift) {
  int64_t staged[CHUNK];
  write_block_size(fp, (uint64_t)n * sizeof(int64_t));
  for (long first = 0; first < n; first += CHUNK) {
    long count = n - first < CHUNK ? n - first : CHUNK;
    for (long i = 0; i < count; i++) staged[i] = first + i + shift;
    fwrite(staged, sizeof(int64_t), (size_t)count, fp);
  }
}

static void write_types_block(FILE *fp, long n) {
  unsigned char staged[CHUNK];
  memset(staged, VTK_VERTEX, sizeof staged);
  write_block_size(fp, (uint64_t)n);
  for (long first = 0; first < n; first += CHUNK)
    fwrite(staged, 1, (size_t)(n - first < CHUNK ? n - first : CHUNK), fp);
}

/* ---- Public ------------------------------------------------------------------------------------------- */

int mica_vtu_write(const char *path, int dim, long n, const double *x, int nfields, const MicaVtkField *fields) {
  MICA_CALL(check_vtu_arguments(path, dim, n, x, nfields, fields));
  MicaOutFile out;
  MICA_CALL(mica_out_open(path, &out));
  write_vtu_header(out.fp, n, nfields, fields);
  for (int f = 0; f < nfields; f++) write_field_block(out.fp, n, &fields[f]);
  write_points_block(out.fp, dim, n, x);
  write_sequence_block(out.fp, n, 0);
  write_sequence_block(out.fp, n, 1);
  write_types_block(out.fp, n);
  fputs("\n  </AppendedData>\n</VTKFile>\n", out.fp);
  MICA_CALL(mica_out_commit(&out)); /* commit reports write errors and removes the temporary file */
  return MICA_SUCCESS;
}

/* The shortest of %.15g .. %.17g that reads back as the same double: "0.1", not "0.10000000000000001". */
static void format_time(double t, char *text, size_t size) {
  for (int digits = 15; digits <= 17; digits++) {
    snprintf(text, size, "%.*g", digits, t);
    if (strtod(text, NULL) == t) return;
  }
}

int mica_pvd_write(const char *path, int nsteps, const double *times, const char *const *files) {
  MICA_CHECK(path && nsteps >= 0 && (nsteps == 0 || (times && files)), MICA_ERR_ARGUMENT,
             "mica_pvd_write: bad arguments");
  for (int s = 0; s < nsteps; s++) {
    MICA_CHECK(files[s], MICA_ERR_ARGUMENT, "mica_pvd_write: file of step %d is NULL", s);
    MICA_CHECK(isfinite(times[s]), MICA_ERR_NUMERIC, "PVD output: time of step %d is not finite", s);
  }
  MicaOutFile out;
  MICA_CALL(mica_out_open(path, &out));
  fprintf(out.fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
                  "  <Collection>\n", host_byte_order());
  for (int s = 0; s < nsteps; s++) {
    char time_text[32];
    format_time(times[s], time_text, sizeof time_text);
    fprintf(out.fp, "    <DataSet timestep=\"%s\" group=\"\" part=\"0\" file=\"", time_text);
    write_escaped(out.fp, files[s]);
    fputs("\"/>\n", out.fp);
  }
  fputs("  </Collection>\n</VTKFile>\n", out.fp);
  MICA_CALL(mica_out_commit(&out));
  return MICA_SUCCESS;
}
