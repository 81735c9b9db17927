/* Reader of Gmsh .msh 4.1 ASCII files (docs/theory.md §geometry, "Gmsh meshes").
 *
 * Reads $MeshFormat (must be 4.1, ASCII), $PhysicalNames (optional), $Entities (entity → physical tags),
 * $Nodes and $Elements (entity blocks); other sections are skipped. Element types: 1 line2, 2 tri3,
 * 3 quad4, 4 tet4, 5 hex8, 15 point. Node tags in elements are resolved to node indices at the end, so
 * sections may come in any order after $MeshFormat. Every error is MICA_ERR_INPUT "file:LINE: what is
 * wrong", LINE being the line of the offending token (or the last line when the file ends early).
 */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "geom_private.h"

enum { TOKEN_MAX = 256, DETAIL_MAX = 768 };

typedef struct {
  const char *path;
  char *buf;
  size_t len, pos;
  long line;       /* line of the current position */
  long token_line; /* line where the last token started */
  const char *section;
} Reader;

/* ---- errors ---- */

static int read_fail(const Reader *rd, long line, const char *fmt, ...) MICA_PRINTF(3, 4);
static int read_fail(const Reader *rd, long line, const char *fmt, ...) {
  char detail[DETAIL_MAX];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(detail, sizeof detail, fmt, ap);
  va_end(ap);
  return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s:%ld: %s", rd->path, line, detail);
}

static int fail_eof(const Reader *rd, const char *what) {
  return read_fail(rd, rd->token_line, "the file ends inside $%s while reading %s (truncated?)", rd->section,
                   what);
}

/* ---- tokens ---- */

static void skip_space(Reader *rd) {
  while (rd->pos < rd->len && (rd->buf[rd->pos] == ' ' || rd->buf[rd->pos] == '\t' ||
                               rd->buf[rd->pos] == '\r' || rd->buf[rd->pos] == '\n')) {
    if (rd->buf[rd->pos] == '\n') rd->line++;
    rd->pos++;
  }
}

/* The next whitespace-separated token (truncated to TOKEN_MAX − 1 characters); 0 at the end of the file. */
static int next_token(Reader *rd, char *tok) {
  size_t n = 0;
  skip_space(rd);
  if (rd->pos >= rd->len) return 0;
  rd->token_line = rd->line;
  while (rd->pos < rd->len && !strchr(" \t\r\n", rd->buf[rd->pos])) {
    if (n < TOKEN_MAX - 1) tok[n++] = rd->buf[rd->pos];
    rd->pos++;
  }
  tok[n] = '\0';
  return 1;
}

static int read_word(Reader *rd, char *tok, const char *what) {
  if (!next_token(rd, tok)) return fail_eof(rd, what);
  return MICA_SUCCESS;
}

static int read_long(Reader *rd, const char *what, long *v) {
  char tok[TOKEN_MAX], *end;
  MICA_CALL(read_word(rd, tok, what));
  errno = 0;
  *v = strtol(tok, &end, 10);
  if (end == tok || *end != '\0' || errno)
    return read_fail(rd, rd->token_line, "expected %s (an integer) in $%s, found '%s'", what, rd->section,
                     tok);
  return MICA_SUCCESS;
}

/* A count: a non-negative integer no larger than the file (every item takes at least one character). */
static int read_count(Reader *rd, const char *what, long *v) {
  MICA_CALL(read_long(rd, what, v));
  if (*v < 0 || (size_t)*v > rd->len)
    return read_fail(rd, rd->token_line, "%s = %ld in $%s is not a plausible count", what, *v, rd->section);
  return MICA_SUCCESS;
}

static int read_int(Reader *rd, const char *what, int *v) {
  long l;
  MICA_CALL(read_long(rd, what, &l));
  if (l < -2147483647L || l > 2147483647L)
    return read_fail(rd, rd->token_line, "%s = %ld in $%s is out of range", what, l, rd->section);
  *v = (int)l;
  return MICA_SUCCESS;
}

static int read_double(Reader *rd, const char *what, double *v) {
  char tok[TOKEN_MAX], *end;
  MICA_CALL(read_word(rd, tok, what));
  *v = strtod(tok, &end);
  if (end == tok || *end != '\0')
    return read_fail(rd, rd->token_line, "expected %s (a number) in $%s, found '%s'", what, rd->section, tok);
  return MICA_SUCCESS;
}

/* A double-quoted string on one line (physical names may contain spaces). */
static int read_quoted(Reader *rd, char *out, size_t size) {
  skip_space(rd);
  if (rd->pos >= rd->len) return fail_eof(rd, "a physical name");
  rd->token_line = rd->line;
  if (rd->buf[rd->pos] != '"') return read_fail(rd, rd->line, "expected a physical name in double quotes");
  size_t n = 0, start = ++rd->pos;
  while (rd->pos < rd->len && rd->buf[rd->pos] != '"' && rd->buf[rd->pos] != '\n') rd->pos++;
  if (rd->pos >= rd->len || rd->buf[rd->pos] != '"')
    return read_fail(rd, rd->token_line, "the physical name has no closing quote");
  n = rd->pos - start;
  rd->pos++;
  if (n >= size)
    return read_fail(rd, rd->token_line, "the physical name is longer than %zu characters", size - 1);
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

/* A name for the message about an unsupported type (Gmsh's numbering of the common ones). */
static const char *unsupported_name(int type) {
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
  default: return "unknown type";
  }
}

/* ---- sections ---- */

static int read_format(Reader *rd) {
  char version[TOKEN_MAX];
  long type, size;
  MICA_CALL(read_word(rd, version, "the version"));
  const long line = rd->token_line;
  if (strcmp(version, "4.1") != 0)
    return read_fail(rd, line,
                     "mesh format version %s is not supported: mica reads Gmsh 4.1 ASCII files "
                     "(gmsh -format msh41, or Mesh.MshFileVersion = 4.1;)",
                     version);
  MICA_CALL(read_long(rd, "the file type", &type));
  if (type != 0)
    return read_fail(rd, rd->token_line,
                     "this is a binary .msh file: mica reads ASCII only (save without "
                     "-bin, or Mesh.Binary = 0;)");
  MICA_CALL(read_long(rd, "the data size", &size));
  return MICA_SUCCESS;
}

static int read_physical_names(Reader *rd, GmshMesh *mesh) {
  long n;
  MICA_CALL(read_count(rd, "numPhysicalNames", &n));
  MICA_FREE(mesh->physicals);
  mesh->nphysicals = 0;
  MICA_CALL(MICA_CALLOC(mesh->physicals, n));
  for (long i = 0; i < n; i++) {
    GmshPhysical *p = &mesh->physicals[i];
    MICA_CALL(read_int(rd, "the physical dimension", &p->dim));
    MICA_CALL(read_int(rd, "the physical tag", &p->tag));
    MICA_CALL(read_quoted(rd, p->name, sizeof p->name));
    mesh->nphysicals++;
  }
  return MICA_SUCCESS;
}

/* Appends a physical tag to entity e of dimension d (its list ends at entity_phys_start[d][e + 1]). */
static int push_physical(GmshMesh *mesh, int d, long e, long *capacity, int tag) {
  long *end = &mesh->entity_phys_start[d][e + 1];
  if (*end >= *capacity) {
    *capacity = 2 * *capacity + 16;
    MICA_CALL(MICA_REALLOC(mesh->entity_phys[d], *capacity));
  }
  mesh->entity_phys[d][(*end)++] = tag;
  return MICA_SUCCESS;
}

/* One entity of dimension d: tag, box (or point), physical tags, bounding entities (skipped). */
static int read_entity(Reader *rd, GmshMesh *mesh, int d, long *capacity) {
  int tag;
  long nphys, nbound;
  double box;
  MICA_CALL(read_int(rd, "an entity tag", &tag));
  for (int k = 0; k < (d == 0 ? 3 : 6); k++) MICA_CALL(read_double(rd, "an entity bounding box", &box));
  MICA_CALL(read_count(rd, "numPhysicalTags", &nphys));
  const long e = mesh->nentities[d];
  mesh->entity_tags[d][e] = tag;
  mesh->entity_phys_start[d][e + 1] = mesh->entity_phys_start[d][e];
  for (long k = 0; k < nphys; k++) {
    int phys;
    MICA_CALL(read_int(rd, "a physical tag", &phys));
    MICA_CALL(push_physical(mesh, d, e, capacity, phys));
  }
  mesh->nentities[d]++;
  if (d == 0) return MICA_SUCCESS;
  MICA_CALL(read_count(rd, "numBounding", &nbound));
  for (long k = 0; k < nbound; k++) {
    int b;
    MICA_CALL(read_int(rd, "a bounding entity tag", &b));
  }
  return MICA_SUCCESS;
}

static int read_entities(Reader *rd, GmshMesh *mesh) {
  long count[4];
  static const char *what[4] = {"numPoints", "numCurves", "numSurfaces", "numVolumes"};
  for (int d = 0; d < 4; d++) MICA_CALL(read_count(rd, what[d], &count[d]));
  for (int d = 0; d < 4; d++) {
    long capacity = 0;
    MICA_FREE(mesh->entity_tags[d]);
    MICA_FREE(mesh->entity_phys_start[d]);
    MICA_FREE(mesh->entity_phys[d]);
    mesh->nentities[d] = 0;
    MICA_CALL(MICA_MALLOC(mesh->entity_tags[d], count[d]));
    MICA_CALL(MICA_CALLOC(mesh->entity_phys_start[d], count[d] + 1));
    MICA_CALL(MICA_MALLOC(mesh->entity_phys[d], 0));
    for (long e = 0; e < count[d]; e++) MICA_CALL(read_entity(rd, mesh, d, &capacity));
  }
  return MICA_SUCCESS;
}

/* Raw node data: tags and the line each was read on, resolved to indices at the end. */
typedef struct {
  long *tag, *line;
  long *elem_tag; /* element node tags before resolution */
  long elem_capacity;
} RawTags;

static int read_nodes(Reader *rd, GmshMesh *mesh, RawTags *raw) {
  long nblocks, nnodes, min_tag, max_tag, count = 0;
  MICA_CALL(read_count(rd, "numEntityBlocks", &nblocks));
  MICA_CALL(read_count(rd, "numNodes", &nnodes));
  MICA_CALL(read_long(rd, "minNodeTag", &min_tag));
  MICA_CALL(read_long(rd, "maxNodeTag", &max_tag));
  MICA_FREE(mesh->x);
  MICA_FREE(raw->tag);
  MICA_FREE(raw->line);
  MICA_CALL(MICA_MALLOC(mesh->x, nnodes * 3));
  MICA_CALL(MICA_MALLOC(raw->tag, nnodes));
  MICA_CALL(MICA_MALLOC(raw->line, nnodes));
  for (long b = 0; b < nblocks; b++) {
    int edim, etag, parametric;
    long n;
    MICA_CALL(read_int(rd, "entityDim", &edim));
    MICA_CALL(read_int(rd, "entityTag", &etag));
    MICA_CALL(read_int(rd, "parametric", &parametric));
    MICA_CALL(read_count(rd, "numNodesInBlock", &n));
    if (count + n > nnodes)
      return read_fail(rd, rd->token_line, "the node blocks hold more nodes than the header's %ld", nnodes);
    for (long i = 0; i < n; i++) {
      long tag;
      MICA_CALL(read_long(rd, "a node tag", &tag));
      if (tag < min_tag || tag > max_tag || tag < 1)
        return read_fail(rd, rd->token_line,
                         "node tag %ld is out of range [%ld, %ld] given in the $Nodes header", tag,
                         min_tag < 1 ? 1 : min_tag, max_tag);
      raw->tag[count + i] = tag;
      raw->line[count + i] = rd->token_line;
    }
    const int extra = parametric ? edim : 0;
    for (long i = 0; i < n; i++) {
      double *x = &mesh->x[(count + i) * 3], u;
      for (int d = 0; d < 3; d++) MICA_CALL(read_double(rd, "a node coordinate", &x[d]));
      for (int d = 0; d < extra; d++) MICA_CALL(read_double(rd, "a parametric coordinate", &u));
    }
    count += n;
  }
  if (count != nnodes)
    return read_fail(rd, rd->token_line, "the node blocks hold %ld nodes, the header says %ld", count,
                     nnodes);
  mesh->nnodes = nnodes;
  return MICA_SUCCESS;
}

static int read_element_block(Reader *rd, GmshMesh *mesh, RawTags *raw, long capacity) {
  int edim, etag, type;
  long n;
  MICA_CALL(read_int(rd, "entityDim", &edim));
  MICA_CALL(read_int(rd, "entityTag", &etag));
  MICA_CALL(read_int(rd, "elementType", &type));
  const long type_line = rd->token_line;
  MICA_CALL(read_count(rd, "numElementsInBlock", &n));
  const int k = gmsh_element_nodes(type);
  if (k == 0)
    return read_fail(rd, type_line,
                     "element type %d (%s) is not supported: mica reads linear elements, types 1 "
                     "(2-node line), 2 (3-node triangle), 3 (4-node quadrangle), 4 (4-node "
                     "tetrahedron), 5 (8-node hexahedron) and 15 (point)",
                     type, unsupported_name(type));
  if (mesh->nelements + n > capacity)
    return read_fail(rd, rd->token_line, "the element blocks hold more elements than the header's %ld",
                     capacity);
  for (long i = 0; i < n; i++) {
    const long e = mesh->nelements;
    long start = mesh->node_start[e];
    MICA_CALL(read_long(rd, "an element tag", &mesh->tag[e]));
    mesh->line[e] = rd->token_line;
    mesh->type[e] = type, mesh->entity_dim[e] = edim, mesh->entity_tag[e] = etag;
    if (start + k > raw->elem_capacity) {
      raw->elem_capacity = 2 * raw->elem_capacity + 4 * k;
      MICA_CALL(MICA_REALLOC(raw->elem_tag, raw->elem_capacity));
    }
    for (int j = 0; j < k; j++) MICA_CALL(read_long(rd, "an element's node tag", &raw->elem_tag[start + j]));
    mesh->node_start[e + 1] = start + k;
    mesh->nelements++;
  }
  return MICA_SUCCESS;
}

static int read_elements(Reader *rd, GmshMesh *mesh, RawTags *raw) {
  long nblocks, nelem, min_tag, max_tag;
  MICA_CALL(read_count(rd, "numEntityBlocks", &nblocks));
  MICA_CALL(read_count(rd, "numElements", &nelem));
  MICA_CALL(read_long(rd, "minElementTag", &min_tag));
  MICA_CALL(read_long(rd, "maxElementTag", &max_tag));
  MICA_CALL(MICA_MALLOC(mesh->type, nelem));
  MICA_CALL(MICA_MALLOC(mesh->entity_dim, nelem));
  MICA_CALL(MICA_MALLOC(mesh->entity_tag, nelem));
  MICA_CALL(MICA_MALLOC(mesh->tag, nelem));
  MICA_CALL(MICA_MALLOC(mesh->line, nelem));
  MICA_CALL(MICA_CALLOC(mesh->node_start, nelem + 1));
  for (long b = 0; b < nblocks; b++) MICA_CALL(read_element_block(rd, mesh, raw, nelem));
  if (mesh->nelements != nelem)
    return read_fail(rd, rd->token_line, "the element blocks hold %ld elements, the header says %ld",
                     mesh->nelements, nelem);
  return MICA_SUCCESS;
}

/* Skips an unknown section up to its $End line. */
static int skip_section(Reader *rd, const char *end) {
  char tok[TOKEN_MAX];
  do {
    MICA_CALL(read_word(rd, tok, end));
  } while (strcmp(tok, end) != 0);
  return MICA_SUCCESS;
}

/* ---- node tags → indices ---- */

typedef struct {
  long tag, index;
} TagIndex;

static int compare_tag(const void *a, const void *b) {
  const long x = ((const TagIndex *)a)->tag, y = ((const TagIndex *)b)->tag;
  return (x > y) - (x < y);
}

static int resolve_nodes(const Reader *rd, GmshMesh *mesh, const RawTags *raw) {
  int ierr = MICA_SUCCESS;
  TagIndex *map = NULL;
  const long nconn = mesh->node_start[mesh->nelements];
  MICA_CALL_CLEANUP(MICA_MALLOC(map, mesh->nnodes));
  for (long i = 0; i < mesh->nnodes; i++) map[i] = (TagIndex){raw->tag[i], i};
  qsort(map, (size_t)mesh->nnodes, sizeof *map, compare_tag);
  for (long i = 1; i < mesh->nnodes; i++)
    if (map[i].tag == map[i - 1].tag) {
      const long later = map[i].index > map[i - 1].index ? map[i].index : map[i - 1].index;
      ierr = read_fail(rd, raw->line[later], "node tag %ld appears twice in $Nodes", map[i].tag);
      goto cleanup;
    }
  MICA_CALL_CLEANUP(MICA_MALLOC(mesh->node, nconn));
  for (long e = 0; e < mesh->nelements; e++)
    for (long j = mesh->node_start[e]; j < mesh->node_start[e + 1]; j++) {
      const TagIndex key = {raw->elem_tag[j], 0};
      const TagIndex *hit = bsearch(&key, map, (size_t)mesh->nnodes, sizeof *map, compare_tag);
      if (!hit) {
        ierr = read_fail(rd, mesh->line[e], "element %ld refers to node %ld, which is not in $Nodes",
                         mesh->tag[e], key.tag);
        goto cleanup;
      }
      mesh->node[j] = hit->index;
    }
cleanup:
  MICA_FREE(map);
  return ierr;
}

/* ---- the file ---- */

static int load_file(const char *path, char **buf, size_t *len) {
  FILE *f = fopen(path, "rb");
  MICA_CHECK(f, MICA_ERR_INPUT, "%s: cannot open the mesh file: %s", path, strerror(errno));
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

/* One section starting at the header token `tok`; checks its $End token. */
static int read_section(Reader *rd, GmshMesh *mesh, RawTags *raw, const char *tok, int *have) {
  char end[TOKEN_MAX + 8], got[TOKEN_MAX];
  const char *name = tok + 1;
  snprintf(end, sizeof end, "$End%s", name);
  rd->section = name;
  if (strcmp(name, "MeshFormat") == 0) return read_fail(rd, rd->token_line, "a second $MeshFormat section");
  if (strcmp(name, "PhysicalNames") == 0) {
    MICA_CALL(read_physical_names(rd, mesh));
  } else if (strcmp(name, "Entities") == 0) {
    MICA_CALL(read_entities(rd, mesh));
    *have |= HAVE_ENTITIES;
  } else if (strcmp(name, "Nodes") == 0) {
    MICA_CALL(read_nodes(rd, mesh, raw));
    *have |= HAVE_NODES;
  } else if (strcmp(name, "Elements") == 0) {
    if (*have & HAVE_ELEMENTS) return read_fail(rd, rd->token_line, "a second $Elements section");
    MICA_CALL(read_elements(rd, mesh, raw));
    *have |= HAVE_ELEMENTS;
  } else {
    return skip_section(rd, end); /* $NodeData, $Periodic, ...: not needed */
  }
  MICA_CALL(read_word(rd, got, end));
  if (strcmp(got, end) != 0)
    return read_fail(rd, rd->token_line, "expected %s, found '%s' (wrong counts in $%s?)", end, got, name);
  return MICA_SUCCESS;
}

static int read_all(Reader *rd, GmshMesh *mesh, RawTags *raw) {
  char tok[TOKEN_MAX];
  int have = 0;
  rd->section = "MeshFormat";
  if (!next_token(rd, tok) || strcmp(tok, "$MeshFormat") != 0)
    return read_fail(rd, rd->token_line, "not a Gmsh mesh: the file must begin with $MeshFormat");
  MICA_CALL(read_format(rd));
  MICA_CALL(read_word(rd, tok, "$EndMeshFormat"));
  if (strcmp(tok, "$EndMeshFormat") != 0)
    return read_fail(rd, rd->token_line, "expected $EndMeshFormat, found '%s'", tok);
  have |= HAVE_FORMAT;
  while (next_token(rd, tok)) {
    if (tok[0] != '$' || strncmp(tok, "$End", 4) == 0)
      return read_fail(rd, rd->token_line, "expected a section header such as $Nodes, found '%s'", tok);
    MICA_CALL(read_section(rd, mesh, raw, tok, &have));
  }
  static const struct {
    int bit;
    const char *name;
  } required[] = {{HAVE_ENTITIES, "$Entities"}, {HAVE_NODES, "$Nodes"}, {HAVE_ELEMENTS, "$Elements"}};
  for (int i = 0; i < 3; i++)
    if (!(have & required[i].bit))
      return read_fail(rd, rd->token_line, "the file ends without a %s section (truncated?)",
                       required[i].name);
  return resolve_nodes(rd, mesh, raw);
}

int gmsh_read(const char *path, GmshMesh *mesh) {
  int ierr = MICA_SUCCESS;
  RawTags raw = {0};
  Reader rd = {.path = path, .line = 1, .token_line = 1};
  memset(mesh, 0, sizeof *mesh);
  snprintf(mesh->path, sizeof mesh->path, "%s", path);
  MICA_CALL(load_file(path, &rd.buf, &rd.len));
  MICA_CALL_CLEANUP(read_all(&rd, mesh, &raw));
cleanup:
  MICA_FREE(rd.buf);
  MICA_FREE(raw.tag);
  MICA_FREE(raw.line);
  MICA_FREE(raw.elem_tag);
  if (ierr) gmsh_free(mesh);
  return ierr;
}

void gmsh_free(GmshMesh *mesh) {
  MICA_FREE(mesh->x);
  MICA_FREE(mesh->type);
  MICA_FREE(mesh->entity_dim);
  MICA_FREE(mesh->entity_tag);
  MICA_FREE(mesh->tag);
  MICA_FREE(mesh->line);
  MICA_FREE(mesh->node_start);
  MICA_FREE(mesh->node);
  MICA_FREE(mesh->physicals);
  for (int d = 0; d < 4; d++) {
    MICA_FREE(mesh->entity_tags[d]);
    MICA_FREE(mesh->entity_phys_start[d]);
    MICA_FREE(mesh->entity_phys[d]);
  }
}

long gmsh_entity_physicals(const GmshMesh *mesh, int dim, int tag, const int **phys) {
  *phys = NULL;
  if (dim < 0 || dim > 3) return 0;
  for (long e = 0; e < mesh->nentities[dim]; e++)
    if (mesh->entity_tags[dim][e] == tag) {
      const long start = mesh->entity_phys_start[dim][e];
      *phys = &mesh->entity_phys[dim][start];
      return mesh->entity_phys_start[dim][e + 1] - start;
    }
  return 0;
}
