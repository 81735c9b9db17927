/* VTU and PVD files for ParaView (vtk.h).
 *
 * A VTU file is VTK's XML UnstructuredGrid with every array in one raw <AppendedData> section: after its
 * '_' marker each array is a UInt64 byte count followed by the bytes, and each DataArray element names
 * its block by offset (bytes from the first byte after '_'). Raw binary keeps full double precision and
 * writes at disk speed, with no base64 or zlib. The cells are either one VTK_VERTEX per point (the particle
 * cloud, which ParaView can show with any filter) or given (a mesh: cells listing shared points, which
 * ParaView colours and contours directly). The data are written in the host's byte order, which the header
 * states. Values and cells are checked before anything is written, and the file goes through files.h, so a
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

/* Nodes of the VTK cell types mica writes (0: a type it does not). */
static int vtk_type_nodes(int type) {
  switch (type) {
  case VTK_VERTEX: return 1;
  case 5: return 3;   /* triangle */
  case 9: return 4;   /* quad */
  case 10: return 4;  /* tetra */
  case 12: return 8;  /* hexahedron */
  case 22: return 6;  /* quadratic triangle */
  case 23: return 8;  /* quadratic quad */
  case 24: return 10; /* quadratic tetra */
  case 25: return 20; /* quadratic hexahedron */
  case 28: return 9;  /* biquadratic quad */
  case 29: return 27; /* triquadratic hexahedron */
  default: return 0;
  }
}

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
    for (int c = 0; fields[f].components && c < fields[f].ncomp; c++)
      MICA_CHECK(fields[f].components[c], MICA_ERR_ARGUMENT, "mica_vtu_write: field '%s' lacks component name %d",
                 fields[f].name, c);
    MICA_CALL(check_finite(fields[f].name, fields[f].data, n * fields[f].ncomp));
  }
  return MICA_SUCCESS;
}

/* Every cell: a known type, its node count, points that exist. */
static int check_cells(long n, const MicaVtkCells *cells) {
  MICA_CHECK(cells->n >= 0 && cells->offsets && cells->offsets[0] == 0 && (cells->n == 0 || (cells->conn && cells->type)),
             MICA_ERR_ARGUMENT, "mica_vtu_write_cells: bad cells (%ld cells)", cells->n);
  for (long c = 0; c < cells->n; c++) {
    const long first = cells->offsets[c], count = cells->offsets[c + 1] - first;
    const int nodes = vtk_type_nodes(cells->type[c]);
    MICA_CHECK(nodes > 0 && count == nodes, MICA_ERR_ARGUMENT,
               "mica_vtu_write_cells: cell %ld has VTK type %d and %ld nodes (the type needs %d)", c,
               (int)cells->type[c], count, nodes);
    for (long k = first; k < first + count; k++)
      MICA_CHECK(cells->conn[k] >= 0 && cells->conn[k] < n, MICA_ERR_ARGUMENT,
                 "mica_vtu_write_cells: cell %ld refers to point %ld of %ld", c, cells->conn[k], n);
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
                                    const char *const *components, uint64_t offset, uint64_t bytes) {
  fprintf(fp, "%s<DataArray type=\"%s\"", indent, type);
  if (name) {
    fputs(" Name=\"", fp);
    write_escaped(fp, name);
    fputc('"', fp);
  }
  if (ncomp > 0) fprintf(fp, " NumberOfComponents=\"%d\"", ncomp);
  for (int c = 0; components && c < ncomp; c++) {
    fprintf(fp, " ComponentName%d=\"", c);
    write_escaped(fp, components[c]);
    fputc('"', fp);
  }
  fprintf(fp, " format=\"appended\" offset=\"%llu\"/>\n", (unsigned long long)offset);
  return offset + sizeof(uint64_t) + bytes;
}

/* Piece header: point data, points, cells, with the blocks in the order they are appended below. */
static void write_vtu_header(FILE *fp, long n, long ncells, long nconn, int nfields, const MicaVtkField *fields) {
  const uint64_t un = (uint64_t)n, uc = (uint64_t)ncells;
  uint64_t offset = 0;
  fprintf(fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"%s\" "
              "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"%ld\" NumberOfCells=\"%ld\">\n"
              "      <PointData>\n", host_byte_order(), n, ncells);
  for (int f = 0; f < nfields; f++)
    offset = write_array_element(fp, "        ", "Float64", fields[f].name, fields[f].ncomp, fields[f].components,
                                 offset, un * (uint64_t)fields[f].ncomp * sizeof(double));
  fputs("      </PointData>\n      <Points>\n", fp);
  offset = write_array_element(fp, "        ", "Float64", NULL, 3, NULL, offset, un * 3 * sizeof(double));
  fputs("      </Points>\n      <Cells>\n", fp);
  offset = write_array_element(fp, "        ", "Int64", "connectivity", 0, NULL, offset, (uint64_t)nconn * sizeof(int64_t));
  offset = write_array_element(fp, "        ", "Int64", "offsets", 0, NULL, offset, uc * sizeof(int64_t));
  write_array_element(fp, "        ", "UInt8", "types", 0, NULL, offset, uc);
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

/* n longs as Int64 (connectivity, or the cells' end offsets), staged through a buffer. */
static void write_long_block(FILE *fp, long n, const long *values) {
  int64_t staged[CHUNK];
  write_block_size(fp, (uint64_t)n * sizeof(int64_t));
  for (long first = 0; first < n; first += CHUNK) {
    long count = n - first < CHUNK ? n - first : CHUNK;
    for (long i = 0; i < count; i++) staged[i] = values[first + i];
    fwrite(staged, sizeof(int64_t), (size_t)count, fp);
  }
}

static void write_cells_blocks(FILE *fp, const MicaVtkCells *cells) {
  write_long_block(fp, cells->offsets[cells->n], cells->conn);
  write_long_block(fp, cells->n, cells->offsets + 1); /* VTK's offsets are where each cell ends */
  write_block_size(fp, (uint64_t)cells->n);
  if (cells->n > 0) fwrite(cells->type, 1, (size_t)cells->n, fp);
}

/* ---- Public ------------------------------------------------------------------------------------------- */

/* cells NULL: one vertex cell per point. */
static int write_vtu(const char *path, int dim, long n, const double *x, const MicaVtkCells *cells, int nfields,
                     const MicaVtkField *fields) {
  MICA_CALL(check_vtu_arguments(path, dim, n, x, nfields, fields));
  if (cells) MICA_CALL(check_cells(n, cells));
  MicaOutFile out;
  MICA_CALL(mica_out_open(path, &out));
  write_vtu_header(out.fp, n, cells ? cells->n : n, cells ? cells->offsets[cells->n] : n, nfields, fields);
  for (int f = 0; f < nfields; f++) write_field_block(out.fp, n, &fields[f]);
  write_points_block(out.fp, dim, n, x);
  if (cells) {
    write_cells_blocks(out.fp, cells);
  } else {
    write_sequence_block(out.fp, n, 0);
    write_sequence_block(out.fp, n, 1);
    write_types_block(out.fp, n);
  }
  fputs("\n  </AppendedData>\n</VTKFile>\n", out.fp);
  MICA_CALL(mica_out_commit(&out)); /* commit reports write errors and removes the temporary file */
  return MICA_SUCCESS;
}

int mica_vtu_write(const char *path, int dim, long n, const double *x, int nfields, const MicaVtkField *fields) {
  return write_vtu(path, dim, n, x, NULL, nfields, fields);
}

int mica_vtu_write_cells(const char *path, int dim, long n, const double *x, const MicaVtkCells *cells, int nfields,
                         const MicaVtkField *fields) {
  MICA_CHECK(cells, MICA_ERR_ARGUMENT, "mica_vtu_write_cells: no cells");
  return write_vtu(path, dim, n, x, cells, nfields, fields);
}

/* The shortest of %.15g .. %.17g that reads back as the same double: "0.1", not "0.10000000000000001". */
static void format_time(double t, char *text, size_t size) {
  for (int digits = 15; digits <= 17; digits++) {
    snprintf(text, size, "%.*g", digits, t);
    if (strtod(text, NULL) == t) return;
  }
}

int mica_pvd_write_parts(const char *path, int nsteps, const double *times, int nparts, const char *const *names,
                         const char *const *files) {
  MICA_CHECK(path && nsteps >= 0 && nparts >= 1 && (nsteps == 0 || (times && files)), MICA_ERR_ARGUMENT,
             "mica_pvd_write: bad arguments");
  for (int s = 0; s < nsteps; s++) {
    for (int p = 0; p < nparts; p++)
      MICA_CHECK(files[s * nparts + p], MICA_ERR_ARGUMENT, "mica_pvd_write: file of step %d, part %d is NULL", s, p);
    MICA_CHECK(isfinite(times[s]), MICA_ERR_NUMERIC, "PVD output: time of step %d is not finite", s);
  }
  MicaOutFile out;
  MICA_CALL(mica_out_open(path, &out));
  fprintf(out.fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
                  "  <Collection>\n", host_byte_order());
  for (int s = 0; s < nsteps; s++) {
    char time_text[32];
    format_time(times[s], time_text, sizeof time_text);
    for (int p = 0; p < nparts; p++) {
      fprintf(out.fp, "    <DataSet timestep=\"%s\" group=\"\" part=\"%d\"", time_text, p);
      if (names && names[p]) {
        fputs(" name=\"", out.fp);
        write_escaped(out.fp, names[p]);
        fputc('"', out.fp);
      }
      fputs(" file=\"", out.fp);
      write_escaped(out.fp, files[s * nparts + p]);
      fputs("\"/>\n", out.fp);
    }
  }
  fputs("  </Collection>\n</VTKFile>\n", out.fp);
  MICA_CALL(mica_out_commit(&out));
  return MICA_SUCCESS;
}

/* A PDataArray element: the array's type, name and components as the pieces declare them. */
static void write_parray(FILE *fp, const char *name, int ncomp, const char *const *components) {
  fputs("      <PDataArray type=\"Float64\"", fp);
  if (name) {
    fputs(" Name=\"", fp);
    write_escaped(fp, name);
    fputc('"', fp);
  }
  fprintf(fp, " NumberOfComponents=\"%d\"", ncomp);
  for (int c = 0; components && c < ncomp; c++) {
    fprintf(fp, " ComponentName%d=\"", c);
    write_escaped(fp, components[c]);
    fputc('"', fp);
  }
  fputs("/>\n", fp);
}

int mica_pvtu_write(const char *path, int nfields, const MicaVtkField *fields, int npieces,
                    const char *const *pieces) {
  MICA_CHECK(path && nfields >= 0 && (nfields == 0 || fields) && npieces >= 1 && pieces, MICA_ERR_ARGUMENT,
             "mica_pvtu_write: bad arguments");
  for (int f = 0; f < nfields; f++)
    MICA_CHECK(fields[f].name && fields[f].ncomp > 0, MICA_ERR_ARGUMENT, "mica_pvtu_write: field %d has no name", f);
  for (int p = 0; p < npieces; p++) MICA_CHECK(pieces[p], MICA_ERR_ARGUMENT, "mica_pvtu_write: piece %d is NULL", p);
  MicaOutFile out;
  MICA_CALL(mica_out_open(path, &out));
  fprintf(out.fp, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PUnstructuredGrid\" version=\"0.1\" byte_order=\"%s\" "
                  "header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n",
          host_byte_order());
  for (int f = 0; f < nfields; f++) write_parray(out.fp, fields[f].name, fields[f].ncomp, fields[f].components);
  fputs("    </PPointData>\n    <PPoints>\n", out.fp);
  write_parray(out.fp, NULL, 3, NULL);
  fputs("    </PPoints>\n", out.fp);
  for (int p = 0; p < npieces; p++) {
    fputs("    <Piece Source=\"", out.fp);
    write_escaped(out.fp, pieces[p]);
    fputs("\"/>\n", out.fp);
  }
  fputs("  </PUnstructuredGrid>\n</VTKFile>\n", out.fp);
  MICA_CALL(mica_out_commit(&out));
  return MICA_SUCCESS;
}

int mica_pvd_write(const char *path, int nsteps, const double *times, const char *const *files) {
  return mica_pvd_write_parts(path, nsteps, times, 1, NULL, files);
}
