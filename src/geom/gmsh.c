/* Reader of Gmsh .msh files (docs/theory.md §geometry, "Gmsh meshes"): MSH 4.1 in ASCII and binary, MSH 2.2 in
 * ASCII (gmsh_v22.c), and the dispatch to a .geo that the Gmsh library meshes (gmsh_geo.c).
 *
 * Reads $MeshFormat (4.1 ASCII or binary, or 2.2 ASCII), $PhysicalNames (optional), $Entities (entity →
 * physical tags), $Nodes and $Elements (entity blocks); other sections are skipped. A 4.1 binary file has the
 * same sections with their numbers in binary (gmsh_reader.h): one reader serves both. Element types: 1 line2,
 * 2 tri3, 3 quad4, 4 tet4, 5 hex8, 15 point. Node tags in elements are resolved to node indices at the end, so
 * sections may come in any order after $MeshFormat. Every error is MICA_ERR_INPUT "file:LINE: what is wrong",
 * LINE being the line of the offending value (or the last line when the file ends early).
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gmsh_reader.h"
#include "mica/sort.h"

enum { DETAIL_MAX = 768 };

/* ---- errors ---- */

int gmsh_fail(const GmshReader *rd, long line, const char *fmt, ...) {
  char detail[DETAIL_MAX];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(detail, sizeof detail, fmt, ap);
  va_end(ap);
  return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s:%ld: %s", rd->path, line, detail);
}

int gmsh_fail_eof(const GmshReader *rd, const char *what) {
  return gmsh_fail(rd, rd->token_line, "the file ends inside $%s while reading %s (truncated?)", rd->section,
                   what);
}

/* ---- ASCII tokens ---- */

static int is_space(char c);

static void skip_space(GmshReader *rd) {
  while (rd->pos < rd->len && is_space(rd->buf[rd->pos])) {
    if (rd->buf[rd->pos] == '\n') rd->line++;
    rd->pos++;
  }
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

/* The next whitespace-separated token (truncated to TOKEN_MAX − 1 characters); 0 at the end of the file. A NUL
 * byte is part of a token, shown as '?', so that it can neither end the string nor stop the reader. */
int gmsh_next_token(GmshReader *rd, char *tok) {
  size_t n = 0;
  skip_space(rd);
  if (rd->pos >= rd->len) return 0;
  rd->token_line = rd->line;
  while (rd->pos < rd->len && !is_space(rd->buf[rd->pos])) {
    if (n < GMSH_TOKEN_MAX - 1) tok[n++] = rd->buf[rd->pos] ? rd->buf[rd->pos] : '?';
    rd->pos++;
  }
  tok[n] = '\0';
  return 1;
}

int gmsh_read_word(GmshReader *rd, char *tok, const char *what) {
  if (!gmsh_next_token(rd, tok)) return gmsh_fail_eof(rd, what);
  return MICA_SUCCESS;
}

/* ---- binary values: n bytes, checked against what is left; the lines they span are counted ---- */

static int take(GmshReader *rd, size_t n, const char *what, void *out) {
  rd->token_line = rd->line;
  if (rd->len - rd->pos < n) return gmsh_fail_eof(rd, what);
  const char *p = rd->buf + rd->pos;
  memcpy(out, p, n);
  for (size_t i = 0; i < n; i++) rd->line += p[i] == '\n';
  rd->pos += n;
  return MICA_SUCCESS;
}

/* Binary data starts after exactly one end of line: whitespace bytes after it belong to the data. */
static int binary_newline(GmshReader *rd) {
  if (rd->pos < rd->len && rd->buf[rd->pos] == '\r') rd->pos++;
  if (rd->pos >= rd->len || rd->buf[rd->pos] != '\n')
    return gmsh_fail(rd, rd->line, "expected the end of the line before the binary data of $%s", rd->section);
  rd->pos++, rd->line++;
  return MICA_SUCCESS;
}

/* ---- values ---- */

int gmsh_read_long(GmshReader *rd, const char *what, long *v) {
  if (rd->binary) {
    uint64_t u = 0;
    MICA_CALL(take(rd, sizeof u, what, &u));
    if (u > (uint64_t)LONG_MAX)
      return gmsh_fail(rd, rd->token_line, "%s = %llu in $%s is out of range", what, (unsigned long long)u,
                       rd->section);
    *v = (long)u;
    return MICA_SUCCESS;
  }
  char tok[GMSH_TOKEN_MAX], *end;
  MICA_CALL(gmsh_read_word(rd, tok, what));
  errno = 0;
  *v = strtol(tok, &end, 10);
  if (end == tok || *end != '\0' || errno)
    return gmsh_fail(rd, rd->token_line, "expected %s (an integer) in $%s, found '%s'", what, rd->section, tok);
  return MICA_SUCCESS;
}

/* A count: a non-negative integer no larger than the bytes left (every item takes at least one), so that no
 * count in a damaged file allocates more than the file's size in items. */
int gmsh_read_count(GmshReader *rd, const char *what, long *v) {
  MICA_CALL(gmsh_read_long(rd, what, v));
  if (*v < 0 || (size_t)*v > rd->len - rd->pos)
    return gmsh_fail(rd, rd->token_line, "%s = %ld in $%s is not a plausible count", what, *v, rd->section);
  return MICA_SUCCESS;
}

int gmsh_read_int(GmshReader *rd, const char *what, int *v) {
  if (rd->binary) {
    int32_t i = 0;
    MICA_CALL(take(rd, sizeof i, what, &i));
    *v = (int)i;
    return MICA_SUCCESS;
  }
  long l;
  MICA_CALL(gmsh_read_long(rd, what, &l));
  if (l < -2147483647L || l > 2147483647L)
    return gmsh_fail(rd, rd->token_line, "%s = %ld in $%s is out of range", what, l, rd->section);
  *v = (int)l;
  return MICA_SUCCESS;
}

int gmsh_read_double(GmshReader *rd, const char *what, double *v) {
  if (rd->binary) {
    MICA_CALL(take(rd, sizeof *v, what, v));
  } else {
    char tok[GMSH_TOKEN_MAX], *end;
    MICA_CALL(gmsh_read_word(rd, tok, what));
    *v = strtod(tok, &end);
    if (end == tok || *end != '\0')
      return gmsh_fail(rd, rd->token_line, "expected %s (a number) in $%s, found '%s'", what, rd->section, tok);
  }
  if (!isfinite(*v)) return gmsh_fail(rd, rd->token_line, "%s in $%s is not a finite number", what, rd->section);
  return MICA_SUCCESS;
}

/* A double-quoted string on one line (physical names may contain spaces). */
static int read_quoted(GmshReader *rd, char *out, size_t size) {
  skip_space(rd);
  if (rd->pos >= rd->len) return gmsh_fail_eof(rd, "a physical name");
  rd->token_line = rd->line;
  if (rd->buf[rd->pos] != '"') return gmsh_fail(rd, rd->line, "expected a physical name in double quotes");
  size_t n = 0, start = ++rd->pos;
  while (rd->pos < rd->len && rd->buf[rd->pos] != '"' && rd->buf[rd->pos] != '\n') rd->pos++;
  if (rd->pos >= rd->len || rd->buf[rd->pos] != '"')
    return gmsh_fail(rd, rd->token_line, "the physical name has no closing quote");
  n = rd->pos - start;
  rd->pos++;
  if (n >= size) return gmsh_fail(rd, rd->token_line, "the physical name is longer than %zu characters", size - 1);
  memcpy(out, rd->buf + start, n);
  out[n] = '\0';
  return MICA_SUCCESS;
}

/* ---- element types ---- */

int gmsh_element_nodes(int type) {
  switch (type) {
  case GMSH_LINE2: return 2;
  case GMSH_TRI3: return 3;
  case GMSH_QUAD4: return 4;
  case GMSH_TET4: return 4;
  case GMSH_HEX8: return 8;
  case GMSH_POINT: return 1;
  default: return 0;
  }
}

int gmsh_element_dim(int type) {
  switch (type) {
  case GMSH_LINE2: return 1;
  case GMSH_TRI3:
  case GMSH_QUAD4: return 2;
  case GMSH_TET4:
  case GMSH_HEX8: return 3;
  default: return 0;
  }
}

/* Gmsh's higher-order types: 8–14 and 16–31 (second to fifth order lines, triangles, quadrangles,
 * tetrahedra, prisms, pyramids), 92 and 93 (third and fourth order hexahedra). */
static int higher_order(int type) {
  return (type >= 8 && type <= 14) || (type >= 16 && type <= 31) || type == 92 || type == 93;
}

/* A name for the message about an unsupported type (Gmsh's numbering of the common ones). */
static const char *type_name(int type) {
  switch (type) {
  case 6: return "6-node prism";
  case 7: return "5-node pyramid";
  case 8: return "3-node second-order line";
  case 9: return "6-node second-order triangle";
  case 10: return "9-node second-order quadrangle";
  case 11: return "10-node second-order tetrahedron";
  case 12: return "27-node second-order hexahedron";
  case 16: return "8-node second-order quadrangle";
  case 17: return "20-node second-order hexahedron";
  default: return higher_order(type) ? "a higher-order element" : "unknown type";
  }
}

void gmsh_type_message(int type, char *out, size_t size) {
  if (higher_order(type))
    snprintf(out, size,
             "element type %d (%s) is not supported: mica's integration cells are linear (straight-sided, "
             "their nodes the particles); re-mesh with first-order elements: gmsh -order 1 (or "
             "Mesh.ElementOrder = 1; in the .geo)",
             type, type_name(type));
  else
    snprintf(out, size,
             "element type %d (%s) is not supported: mica reads linear elements, types 1 (2-node line), 2 "
             "(3-node triangle), 3 (4-node quadrangle), 4 (4-node tetrahedron), 5 (8-node hexahedron) and 15 "
             "(point)",
             type, type_name(type));
}

int gmsh_fail_type(const GmshReader *rd, long line, int type) {
  char msg[DETAIL_MAX];
  gmsh_type_message(type, msg, sizeof msg);
  return gmsh_fail(rd, line, "%s", msg);
}

/* ---- entities ---- */

int gmsh_entities_alloc(GmshMesh *mesh, const long count[4]) {
  for (int d = 0; d < 4; d++) {
    MICA_FREE(mesh->entity_index[d]);
    MICA_FREE(mesh->entity_tags[d]);
    MICA_FREE(mesh->entity_phys_start[d]);
    MICA_FREE(mesh->entity_phys[d]);
    mesh->nentities[d] = 0;
    MICA_CALL(MICA_MALLOC(mesh->entity_tags[d], count[d]));
    MICA_CALL(MICA_CALLOC(mesh->entity_phys_start[d], count[d] + 1));
    MICA_CALL(MICA_MALLOC(mesh->entity_phys[d], 0));
  }
  return MICA_SUCCESS;
}

void gmsh_entity_begin(GmshMesh *mesh, int d, int tag) {
  const long e = mesh->nentities[d]++;
  mesh->entity_tags[d][e] = tag;
  mesh->entity_phys_start[d][e + 1] = mesh->entity_phys_start[d][e];
}

int gmsh_entity_push(GmshMesh *mesh, int d, long *capacity, int phys) {
  long *end = &mesh->entity_phys_start[d][mesh->nentities[d]];
  if (*end >= *capacity) {
    *capacity = 2 * *capacity + 16;
    MICA_CALL(MICA_REALLOC(mesh->entity_phys[d], *capacity));
  }
  mesh->entity_phys[d][(*end)++] = phys;
  return MICA_SUCCESS;
}

int gmsh_reserve_element_nodes(GmshRawTags *raw, long need) {
  if (need <= raw->elem_capacity) return MICA_SUCCESS;
  raw->elem_capacity = 2 * raw->elem_capacity + need;
  MICA_CALL(MICA_REALLOC(raw->elem_tag, raw->elem_capacity));
  return MICA_SUCCESS;
}

/* ---- sections ---- */

typedef struct {
  int v22;    /* MSH 2.2 */
  int binary; /* file type 1 */
} Format;

/* The binary integer 1 after the header tells the writer's byte order. */
static int check_byte_order(GmshReader *rd) {
  uint32_t one = 0;
  MICA_CALL(take(rd, sizeof one, "the byte-order integer", &one));
  if (one == 1) return MICA_SUCCESS;
  const uint32_t swapped = (one >> 24) | ((one >> 8) & 0xff00u) | ((one << 8) & 0xff0000u) | (one << 24);
  if (swapped == 1)
    return gmsh_fail(rd, rd->token_line,
                     "the binary file was written on a machine of the other byte order: save it as ASCII "
                     "(without -bin, or Mesh.Binary = 0;)");
  return gmsh_fail(rd, rd->token_line,
                   "expected the binary integer 1 after '4.1 1 8', found 0x%08x: the file is damaged", one);
}

static int read_format(GmshReader *rd, Format *fmt) {
  char version[GMSH_TOKEN_MAX];
  long type, size;
  MICA_CALL(gmsh_read_word(rd, version, "the version"));
  fmt->v22 = !strcmp(version, "2.2");
  if (strcmp(version, "4.1") != 0 && !fmt->v22)
    return gmsh_fail(rd, rd->token_line,
                     "mesh format version %s is not supported: mica reads Gmsh 4.1 (ASCII or binary) and 2.2 "
                     "(ASCII) files (gmsh -format msh41, or Mesh.MshFileVersion = 4.1;)",
                     version);
  MICA_CALL(gmsh_read_long(rd, "the file type", &type));
  if (type != 0 && type != 1)
    return gmsh_fail(rd, rd->token_line, "file type %ld: expected 0 (ASCII) or 1 (binary)", type);
  if (type == 1 && fmt->v22)
    return gmsh_fail(rd, rd->token_line,
                     "this is a binary 2.2 file: mica reads 2.2 files in ASCII (save without -bin, or "
                     "Mesh.Binary = 0;) and 4.1 files in either (gmsh -format msh41)");
  MICA_CALL(gmsh_read_long(rd, "the data size", &size));
  fmt->binary = type == 1;
  if (!fmt->binary) return MICA_SUCCESS;
  if (size != 8)
    return gmsh_fail(rd, rd->token_line,
                     "data size %ld: mica reads binary files whose size_t has 8 bytes (64-bit Gmsh); save the "
                     "mesh as ASCII (without -bin, or Mesh.Binary = 0;)",
                     size);
  MICA_CALL(binary_newline(rd));
  return check_byte_order(rd);
}

static int read_physical_names(GmshReader *rd, GmshMesh *mesh) {
  long n;
  MICA_CALL(gmsh_read_count(rd, "numPhysicalNames", &n));
  MICA_FREE(mesh->physicals);
  mesh->nphysicals = 0;
  MICA_CALL(MICA_CALLOC(mesh->physicals, n));
  for (long i = 0; i < n; i++) {
    GmshPhysical *p = &mesh->physicals[i];
    MICA_CALL(gmsh_read_int(rd, "the physical dimension", &p->dim));
    MICA_CALL(gmsh_read_int(rd, "the physical tag", &p->tag));
    MICA_CALL(read_quoted(rd, p->name, sizeof p->name));
    mesh->nphysicals++;
  }
  return MICA_SUCCESS;
}

/* One entity of dimension d: tag, box (or point), physical tags, bounding entities (skipped). */
static int read_entity(GmshReader *rd, GmshMesh *mesh, int d, long *capacity) {
  int tag;
  long nphys, nbound;
  double box;
  MICA_CALL(gmsh_read_int(rd, "an entity tag", &tag));
  for (int k = 0; k < (d == 0 ? 3 : 6); k++) MICA_CALL(gmsh_read_double(rd, "an entity bounding box", &box));
  MICA_CALL(gmsh_read_count(rd, "numPhysicalTags", &nphys));
  gmsh_entity_begin(mesh, d, tag);
  for (long k = 0; k < nphys; k++) {
    int phys;
    MICA_CALL(gmsh_read_int(rd, "a physical tag", &phys));
    MICA_CALL(gmsh_entity_push(mesh, d, capacity, phys));
  }
  if (d == 0) return MICA_SUCCESS;
  MICA_CALL(gmsh_read_count(rd, "numBounding", &nbound));
  for (long k = 0; k < nbound; k++) {
    int b;
    MICA_CALL(gmsh_read_int(rd, "a bounding entity tag", &b));
  }
  return MICA_SUCCESS;
}

static int read_entities(GmshReader *rd, GmshMesh *mesh) {
  long count[4];
  static const char *what[4] = {"numPoints", "numCurves", "numSurfaces", "numVolumes"};
  for (int d = 0; d < 4; d++) MICA_CALL(gmsh_read_count(rd, what[d], &count[d]));
  MICA_CALL(gmsh_entities_alloc(mesh, count));
  for (int d = 0; d < 4; d++) {
    long capacity = 0;
    for (long e = 0; e < count[d]; e++) MICA_CALL(read_entity(rd, mesh, d, &capacity));
  }
  return MICA_SUCCESS;
}

/* Grows the node arrays to `need` slots. */
static int reserve_nodes(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long need) {
  if (need <= raw->node_capacity) return MICA_SUCCESS;
  const long capacity = rd->filter ? 2 * raw->node_capacity + 1024 : need;
  MICA_CALL(MICA_REALLOC(mesh->x, capacity * 3));
  MICA_CALL(MICA_REALLOC(raw->tag, capacity));
  MICA_CALL(MICA_REALLOC(raw->line, capacity));
  if (rd->filter) MICA_CALL(MICA_REALLOC(mesh->node_key, capacity));
  raw->node_capacity = capacity;
  return MICA_SUCCESS;
}

int gmsh_nodes_alloc(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long n) {
  MICA_FREE(mesh->x);
  MICA_FREE(mesh->node_key);
  MICA_FREE(raw->tag);
  MICA_FREE(raw->line);
  mesh->nnodes = 0, raw->node_capacity = 0;
  return reserve_nodes(rd, mesh, raw, rd->filter ? 1 : n);
}

int gmsh_node_add(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long tag, long line, const double x[3],
                  long key) {
  if (rd->filter) rd->filter->nodes_read++;
  if (rd->filter && !rd->filter->keep(x, rd->filter->ctx)) return MICA_SUCCESS;
  MICA_CALL(reserve_nodes(rd, mesh, raw, mesh->nnodes + 1));
  const long i = mesh->nnodes++;
  raw->tag[i] = tag, raw->line[i] = line;
  memcpy(mesh->x + i * 3, x, sizeof(double) * 3);
  if (rd->filter) mesh->node_key[i] = key;
  return MICA_SUCCESS;
}

/* A block's node tags come before its coordinates: a second cursor reads each tag again beside its node's
 * coordinates, so that a filter keeps a node's tag without holding the block's. */
static int read_nodes(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  long nblocks, nnodes, min_tag, max_tag, count = 0;
  MICA_CALL(gmsh_read_count(rd, "numEntityBlocks", &nblocks));
  MICA_CALL(gmsh_read_count(rd, "numNodes", &nnodes));
  MICA_CALL(gmsh_read_long(rd, "minNodeTag", &min_tag));
  MICA_CALL(gmsh_read_long(rd, "maxNodeTag", &max_tag));
  MICA_CALL(gmsh_nodes_alloc(rd, mesh, raw, nnodes));
  for (long b = 0; b < nblocks; b++) {
    int edim, etag, parametric;
    long n;
    MICA_CALL(gmsh_read_int(rd, "entityDim", &edim));
    MICA_CALL(gmsh_read_int(rd, "entityTag", &etag));
    MICA_CALL(gmsh_read_int(rd, "parametric", &parametric));
    MICA_CALL(gmsh_read_count(rd, "numNodesInBlock", &n));
    if (count + n > nnodes)
      return gmsh_fail(rd, rd->token_line, "the node blocks hold more nodes than the header's %ld", nnodes);
    GmshReader tags = *rd; /* at the block's first tag */
    for (long i = 0; i < n; i++) {
      long tag;
      MICA_CALL(gmsh_read_long(rd, "a node tag", &tag));
      if (tag < min_tag || tag > max_tag || tag < 1)
        return gmsh_fail(rd, rd->token_line, "node tag %ld is out of range [%ld, %ld] given in the $Nodes header",
                         tag, min_tag < 1 ? 1 : min_tag, max_tag);
    }
    const int extra = parametric ? (edim < 0 ? 0 : edim > 3 ? 3 : edim) : 0;
    for (long i = 0; i < n; i++) {
      double x[3], u;
      long tag;
      for (int d = 0; d < 3; d++) MICA_CALL(gmsh_read_double(rd, "a node coordinate", &x[d]));
      for (int d = 0; d < extra; d++) MICA_CALL(gmsh_read_double(rd, "a parametric coordinate", &u));
      MICA_CALL(gmsh_read_long(&tags, "a node tag", &tag));
      MICA_CALL(gmsh_node_add(rd, mesh, raw, tag, tags.token_line, x, count + i));
    }
    count += n;
  }
  if (count != nnodes)
    return gmsh_fail(rd, rd->token_line, "the node blocks hold %ld nodes, the header says %ld", count, nnodes);
  return MICA_SUCCESS;
}

/* ---- elements ---- */

int gmsh_mesh_grow_elements(GmshMesh *mesh, long capacity) {
  const int first = mesh->node_start == NULL;
  MICA_CALL(MICA_REALLOC(mesh->type, capacity + 1));
  MICA_CALL(MICA_REALLOC(mesh->entity_dim, capacity + 1));
  MICA_CALL(MICA_REALLOC(mesh->entity_tag, capacity + 1));
  MICA_CALL(MICA_REALLOC(mesh->tag, capacity + 1));
  MICA_CALL(MICA_REALLOC(mesh->line, capacity + 1));
  MICA_CALL(MICA_REALLOC(mesh->node_start, capacity + 1));
  if (first) mesh->node_start[0] = 0;
  return MICA_SUCCESS;
}

/* The arrays of `capacity` elements, and 2.2's physical tags beside them. */
static int grow_elements(GmshMesh *mesh, GmshRawTags *raw, long capacity) {
  MICA_CALL(gmsh_mesh_grow_elements(mesh, capacity));
  MICA_CALL(MICA_REALLOC(raw->elem_phys, capacity + 1));
  raw->elements_capacity = capacity;
  return MICA_SUCCESS;
}

int gmsh_elements_alloc(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long n) {
  raw->elements_capacity = 0, raw->elements_read = 0;
  mesh->nelements = 0;
  return grow_elements(mesh, raw, rd->filter ? 0 : n); /* a filter: grown as elements are kept */
}

int gmsh_element_reserve(GmshMesh *mesh, GmshRawTags *raw) {
  if (mesh->nelements < raw->elements_capacity) return MICA_SUCCESS;
  return grow_elements(mesh, raw, 2 * raw->elements_capacity + 1024);
}

int gmsh_element_kept(GmshReader *rd, GmshRawTags *raw, int type, const long *tags, int k) {
  raw->elements_read++;
  if (!rd->filter) return 1;
  if (gmsh_element_dim(type) > rd->filter->max_dim) rd->filter->max_dim = gmsh_element_dim(type);
  rd->filter->elements_of_dim[gmsh_element_dim(type) & 3]++;
  for (int j = 0; j < k; j++)
    if (!bsearch(&tags[j], raw->kept_tags, (size_t)raw->nkept_tags, sizeof(long), mica_compare_long)) return 0;
  return 1;
}

static int read_element_block(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long capacity) {
  int edim, etag, type;
  long n;
  MICA_CALL(gmsh_read_int(rd, "entityDim", &edim));
  MICA_CALL(gmsh_read_int(rd, "entityTag", &etag));
  MICA_CALL(gmsh_read_int(rd, "elementType", &type));
  const long type_line = rd->token_line;
  MICA_CALL(gmsh_read_count(rd, "numElementsInBlock", &n));
  const int k = gmsh_element_nodes(type);
  if (k == 0) return gmsh_fail_type(rd, type_line, type);
  if (raw->elements_read + n > capacity)
    return gmsh_fail(rd, rd->token_line, "the element blocks hold more elements than the header's %ld",
                     capacity);
  for (long i = 0; i < n; i++) {
    long tag, tags[GMSH_NODES_MAX];
    MICA_CALL(gmsh_read_long(rd, "an element tag", &tag));
    const long line = rd->token_line;
    for (int j = 0; j < k; j++) MICA_CALL(gmsh_read_long(rd, "an element's node tag", &tags[j]));
    if (!gmsh_element_kept(rd, raw, type, tags, k)) continue;
    MICA_CALL(gmsh_element_reserve(mesh, raw));
    const long e = mesh->nelements, start = mesh->node_start[e];
    mesh->tag[e] = tag, mesh->line[e] = line;
    mesh->type[e] = type, mesh->entity_dim[e] = edim, mesh->entity_tag[e] = etag;
    MICA_CALL(gmsh_reserve_element_nodes(raw, start + k));
    memcpy(&raw->elem_tag[start], tags, sizeof(long) * (size_t)k);
    mesh->node_start[e + 1] = start + k;
    mesh->nelements++;
  }
  return MICA_SUCCESS;
}

static int read_elements(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  long nblocks, nelem, min_tag, max_tag;
  MICA_CALL(gmsh_read_count(rd, "numEntityBlocks", &nblocks));
  MICA_CALL(gmsh_read_count(rd, "numElements", &nelem));
  MICA_CALL(gmsh_read_long(rd, "minElementTag", &min_tag));
  MICA_CALL(gmsh_read_long(rd, "maxElementTag", &max_tag));
  MICA_CALL(gmsh_elements_alloc(rd, mesh, raw, nelem));
  for (long b = 0; b < nblocks; b++) MICA_CALL(read_element_block(rd, mesh, raw, nelem));
  if (raw->elements_read != nelem)
    return gmsh_fail(rd, rd->token_line, "the element blocks hold %ld elements, the header says %ld",
                     raw->elements_read, nelem);
  return MICA_SUCCESS;
}

/* Skips an unknown section up to its $End line: by tokens in ASCII, by searching the bytes for a line that
 * begins with `end` in a binary file (whose sections may hold any byte). */
static int skip_section(GmshReader *rd, const char *end, int binary) {
  char tok[GMSH_TOKEN_MAX];
  if (!binary) {
    do {
      MICA_CALL(gmsh_read_word(rd, tok, end));
    } while (strcmp(tok, end) != 0);
    return MICA_SUCCESS;
  }
  const size_t n = strlen(end);
  rd->token_line = rd->line;
  for (size_t p = rd->pos; p < rd->len; p++) {
    if (rd->buf[p] == '\n') {
      rd->line++;
    } else if (rd->buf[p - 1] == '\n' && rd->len - p >= n && memcmp(rd->buf + p, end, n) == 0 &&
               (rd->len - p == n || is_space(rd->buf[p + n]))) {
      rd->pos = p + n;
      return MICA_SUCCESS;
    }
  }
  return gmsh_fail_eof(rd, end);
}

/* ---- node tags → indices ---- */

typedef struct {
  long tag, index;
} TagIndex;

static int compare_tag(const void *a, const void *b) {
  const long x = ((const TagIndex *)a)->tag, y = ((const TagIndex *)b)->tag;
  return (x > y) - (x < y);
}

int gmsh_resolve_nodes(const GmshReader *rd, GmshMesh *mesh, const GmshRawTags *raw) {
  int ierr = MICA_SUCCESS;
  TagIndex *map = NULL;
  const long nconn = mesh->node_start[mesh->nelements];
  MICA_CALL_CLEANUP(MICA_MALLOC(map, mesh->nnodes));
  for (long i = 0; i < mesh->nnodes; i++) map[i] = (TagIndex){raw->tag[i], i};
  qsort(map, (size_t)mesh->nnodes, sizeof *map, compare_tag);
  for (long i = 1; i < mesh->nnodes; i++)
    if (map[i].tag == map[i - 1].tag) {
      const long later = map[i].index > map[i - 1].index ? map[i].index : map[i - 1].index;
      ierr = gmsh_fail(rd, raw->line[later], "node tag %ld appears twice in $Nodes", map[i].tag);
      goto cleanup;
    }
  MICA_CALL_CLEANUP(MICA_MALLOC(mesh->node, nconn));
  for (long e = 0; e < mesh->nelements; e++)
    for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++) {
      const TagIndex key = {raw->elem_tag[j], 0};
      const TagIndex *hit = bsearch(&key, map, (size_t)mesh->nnodes, sizeof *map, compare_tag);
      if (!hit) {
        ierr = gmsh_fail(rd, mesh->line[e], "element %ld refers to node %ld, which is not in $Nodes", mesh->tag[e],
                         key.tag);
        goto cleanup;
      }
      mesh->node[j] = hit->index;
    }
cleanup:
  MICA_FREE(map);
  return ierr;
}

/* ---- the file ---- */

int gmsh_load_file(const char *path, const char *what, char **buf, size_t *len) {
  FILE *f = fopen(path, "rb");
  MICA_CHECK(f, MICA_ERR_INPUT, "%s: cannot open the %s: %s", path, what, strerror(errno));
  int ierr = MICA_SUCCESS;
  size_t cap = 1 << 16, n = 0, got;
  *buf = NULL;
  MICA_CALL_CLEANUP(MICA_MALLOC(*buf, cap + 1));
  while ((got = fread(*buf + n, 1, cap - n, f)) > 0) {
    n += got;
    if (n == cap) {
      cap *= 2;
      MICA_CALL_CLEANUP(MICA_REALLOC(*buf, cap + 1));
    }
  }
  if (ferror(f)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "%s: read error", path);
    goto cleanup;
  }
  (*buf)[n] = '\0';
  *len = n;
cleanup:
  fclose(f);
  if (ierr) MICA_FREE(*buf);
  return ierr;
}

enum { HAVE_FORMAT = 1, HAVE_ENTITIES = 2, HAVE_NODES = 4, HAVE_ELEMENTS = 8 };

/* A section whose numbers are binary in a binary file begins after its header's end of line. */
static int begin_data(GmshReader *rd, const Format *fmt) {
  if (fmt->binary) MICA_CALL(binary_newline(rd));
  rd->binary = fmt->binary;
  return MICA_SUCCESS;
}

/* A filter: the kept nodes' tags, sorted, before the elements are read (each checked against them as it is read). */
static int kept_tags(const GmshReader *rd, const GmshMesh *mesh, GmshRawTags *raw, int have) {
  if (!(have & HAVE_NODES))
    return gmsh_fail(rd, rd->token_line, "$Elements before $Nodes: a distributed run reads the nodes first; "
                     "write the mesh with Gmsh (which puts $Nodes first)");
  MICA_FREE(raw->kept_tags);
  MICA_CALL(MICA_MALLOC(raw->kept_tags, mesh->nnodes + 1));
  memcpy(raw->kept_tags, raw->tag, sizeof(long) * (size_t)mesh->nnodes);
  qsort(raw->kept_tags, (size_t)mesh->nnodes, sizeof(long), mica_compare_long);
  raw->nkept_tags = mesh->nnodes;
  return MICA_SUCCESS;
}

static int read_data_section(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, const Format *fmt, int *have) {
  const char *name = rd->section;
  if (strcmp(name, "Entities") == 0) {
    MICA_CALL(begin_data(rd, fmt));
    MICA_CALL(read_entities(rd, mesh));
    *have |= HAVE_ENTITIES;
  } else if (strcmp(name, "Nodes") == 0) {
    MICA_CALL(begin_data(rd, fmt));
    MICA_CALL(fmt->v22 ? gmsh_v22_nodes(rd, mesh, raw) : read_nodes(rd, mesh, raw));
    *have |= HAVE_NODES;
  } else {
    if (*have & HAVE_ELEMENTS) return gmsh_fail(rd, rd->token_line, "a second $Elements section");
    if (rd->filter) MICA_CALL(kept_tags(rd, mesh, raw, *have));
    MICA_CALL(begin_data(rd, fmt));
    MICA_CALL(fmt->v22 ? gmsh_v22_elements(rd, mesh, raw) : read_elements(rd, mesh, raw));
    *have |= HAVE_ELEMENTS;
  }
  rd->binary = 0;
  return MICA_SUCCESS;
}

/* One section starting at the header token `tok`; checks its $End token. */
static int read_section(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, const char *tok, const Format *fmt,
                        int *have) {
  char end[GMSH_TOKEN_MAX + 8], got[GMSH_TOKEN_MAX];
  const char *name = tok + 1;
  snprintf(end, sizeof end, "$End%s", name);
  rd->section = name;
  if (strcmp(name, "MeshFormat") == 0) return gmsh_fail(rd, rd->token_line, "a second $MeshFormat section");
  const int data = (strcmp(name, "Entities") == 0 && !fmt->v22) || strcmp(name, "Nodes") == 0 ||
                   strcmp(name, "Elements") == 0;
  if (strcmp(name, "PhysicalNames") == 0)
    MICA_CALL(read_physical_names(rd, mesh));
  else if (data)
    MICA_CALL(read_data_section(rd, mesh, raw, fmt, have));
  else
    return skip_section(rd, end, fmt->binary); /* $NodeData, $Periodic, ...: not needed */
  MICA_CALL(gmsh_read_word(rd, got, end));
  if (strcmp(got, end) != 0)
    return gmsh_fail(rd, rd->token_line, "expected %s, found '%s' (wrong counts in $%s?)", end, got, name);
  return MICA_SUCCESS;
}

static int read_all(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  char tok[GMSH_TOKEN_MAX];
  int have = 0;
  Format fmt = {0};
  rd->section = "MeshFormat";
  if (!gmsh_next_token(rd, tok) || strcmp(tok, "$MeshFormat") != 0)
    return gmsh_fail(rd, rd->token_line, "not a Gmsh mesh: the file must begin with $MeshFormat");
  MICA_CALL(read_format(rd, &fmt));
  MICA_CALL(gmsh_read_word(rd, tok, "$EndMeshFormat"));
  if (strcmp(tok, "$EndMeshFormat") != 0)
    return gmsh_fail(rd, rd->token_line, "expected $EndMeshFormat, found '%s'", tok);
  have |= HAVE_FORMAT;
  while (gmsh_next_token(rd, tok)) {
    if (tok[0] != '$' || strncmp(tok, "$End", 4) == 0)
      return gmsh_fail(rd, rd->token_line, "expected a section header such as $Nodes, found '%s'", tok);
    MICA_CALL(read_section(rd, mesh, raw, tok, &fmt, &have));
  }
  static const struct {
    int bit;
    const char *name;
  } required[] = {{HAVE_ENTITIES, "$Entities"}, {HAVE_NODES, "$Nodes"}, {HAVE_ELEMENTS, "$Elements"}};
  for (int i = fmt.v22 ? 1 : 0; i < 3; i++)
    if (!(have & required[i].bit))
      return gmsh_fail(rd, rd->token_line, "the file ends without a %s section (truncated?)", required[i].name);
  if (fmt.v22) MICA_CALL(gmsh_v22_entities(mesh, raw, rd->filter != NULL));
  return gmsh_resolve_nodes(rd, mesh, raw);
}

/* A name ending in .geo (any case) is a Gmsh script for the library to mesh; anything else is a .msh file. */
static int is_geo(const char *path) {
  const size_t n = strlen(path);
  return n > 4 && path[n - 4] == '.' && (path[n - 3] | 32) == 'g' && (path[n - 2] | 32) == 'e' &&
         (path[n - 1] | 32) == 'o';
}

static int compare_entity_key(const void *a, const void *b) {
  const GmshEntityKey *x = a, *y = b;
  if (x->tag != y->tag) return (x->tag > y->tag) - (x->tag < y->tag);
  return (x->entity > y->entity) - (x->entity < y->entity);
}

/* mesh->entity_index of every dimension, from the entity tables however they were filled. */
static int index_entities(GmshMesh *mesh) {
  for (int d = 0; d < 4; d++) {
    const long n = mesh->nentities[d];
    MICA_FREE(mesh->entity_index[d]);
    MICA_CALL(MICA_MALLOC(mesh->entity_index[d], n));
    for (long e = 0; e < n; e++) mesh->entity_index[d][e] = (GmshEntityKey){mesh->entity_tags[d][e], e};
    qsort(mesh->entity_index[d], (size_t)n, sizeof *mesh->entity_index[d], compare_entity_key);
  }
  return MICA_SUCCESS;
}

/* The file mapped read-only (not copied: the ranks of a distributed run share its pages); an empty file maps to an
 * empty buffer. */
static int map_file(const char *path, const char **buf, size_t *len) {
  const int fd = open(path, O_RDONLY);
  MICA_CHECK(fd >= 0, MICA_ERR_INPUT, "%s: cannot open the mesh file: %s", path, strerror(errno));
  struct stat st;
  int ierr = MICA_SUCCESS;
  *buf = "", *len = 0;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s: not a regular file", path);
  } else if (st.st_size > 0) {
    void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED)
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_IO, "%s: cannot map the mesh file: %s", path,
                            strerror(errno));
    else
      *buf = p, *len = (size_t)st.st_size;
  }
  close(fd);
  return ierr;
}

static void unmap_file(const char *buf, size_t len) {
  if (len > 0) munmap((void *)(uintptr_t)buf, len);
}

static void raw_free(GmshRawTags *raw) {
  MICA_FREE(raw->tag);
  MICA_FREE(raw->line);
  MICA_FREE(raw->elem_tag);
  MICA_FREE(raw->elem_phys);
  MICA_FREE(raw->kept_tags);
  MICA_FREE(raw->groups);
}

/* A .msh file through the filter (NULL: all of it). */
static int read_msh(const char *path, GmshFilter *filter, GmshMesh *mesh) {
  int ierr = MICA_SUCCESS;
  GmshRawTags raw = {0};
  GmshReader rd = {.path = path, .line = 1, .token_line = 1, .filter = filter};
  MICA_CALL(map_file(path, &rd.buf, &rd.len));
  MICA_CALL_CLEANUP(read_all(&rd, mesh, &raw));
  MICA_CALL_CLEANUP(index_entities(mesh));
cleanup:
  unmap_file(rd.buf, rd.len);
  raw_free(&raw);
  return ierr;
}

int gmsh_read(const char *path, double size_factor, GmshMesh *mesh) {
  int ierr = MICA_SUCCESS;
  memset(mesh, 0, sizeof *mesh);
  snprintf(mesh->path, sizeof mesh->path, "%s", path);
  if (is_geo(path)) {
    MICA_CALL_CLEANUP(gmsh_geo_mesh(path, size_factor, mesh));
    MICA_CALL_CLEANUP(index_entities(mesh));
  } else {
    MICA_CHECK(size_factor == 0, MICA_ERR_INPUT,
               "%s: a mesh size factor applies to a .geo that mica meshes, not to a mesh file", path);
    MICA_CALL_CLEANUP(read_msh(path, NULL, mesh));
  }
cleanup:
  if (ierr) gmsh_free(mesh);
  return ierr;
}

int gmsh_read_filtered(const char *path, GmshFilter *filter, GmshMesh *mesh) {
  memset(mesh, 0, sizeof *mesh);
  snprintf(mesh->path, sizeof mesh->path, "%s", path);
  MICA_CHECK(!is_geo(path), MICA_ERR_ARGUMENT, "gmsh_read_filtered: %s is a .geo, not a mesh file", path);
  filter->max_dim = 0, filter->nodes_read = 0;
  memset(filter->elements_of_dim, 0, sizeof filter->elements_of_dim);
  const int ierr = read_msh(path, filter, mesh);
  if (ierr) gmsh_free(mesh);
  return ierr;
}

int gmsh_is_geo(const char *path) { return is_geo(path); }

void gmsh_free(GmshMesh *mesh) {
  MICA_FREE(mesh->x);
  MICA_FREE(mesh->type);
  MICA_FREE(mesh->entity_dim);
  MICA_FREE(mesh->entity_tag);
  MICA_FREE(mesh->tag);
  MICA_FREE(mesh->line);
  MICA_FREE(mesh->node_start);
  MICA_FREE(mesh->node);
  MICA_FREE(mesh->node_key);
  MICA_FREE(mesh->physicals);
  for (int d = 0; d < 4; d++) {
    MICA_FREE(mesh->entity_index[d]);
    MICA_FREE(mesh->entity_tags[d]);
    MICA_FREE(mesh->entity_phys_start[d]);
    MICA_FREE(mesh->entity_phys[d]);
  }
}

long gmsh_entity_physicals(const GmshMesh *mesh, int dim, int tag, const int **phys) {
  *phys = NULL;
  if (dim < 0 || dim > 3) return 0;
  const GmshEntityKey *index = mesh->entity_index[dim];
  long lo = 0, hi = mesh->nentities[dim]; /* the first key whose tag is not below `tag` */
  while (lo < hi) {
    const long mid = lo + (hi - lo) / 2;
    if (index[mid].tag < tag) lo = mid + 1;
    else hi = mid;
  }
  if (lo == mesh->nentities[dim] || index[lo].tag != tag) return 0;
  const long e = index[lo].entity, start = mesh->entity_phys_start[dim][e];
  *phys = &mesh->entity_phys[dim][start];
  return mesh->entity_phys_start[dim][e + 1] - start;
}

void gmsh_where(const GmshMesh *mesh, long e, char *out, size_t size) {
  if (mesh->line && mesh->line[e] > 0)
    snprintf(out, size, "%s:%ld", mesh->path, mesh->line[e]);
  else
    snprintf(out, size, "%s (as meshed by Gmsh)", mesh->path);
}
