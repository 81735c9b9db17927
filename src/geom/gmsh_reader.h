/* The .msh reader's internals, shared by gmsh.c (the file, $MeshFormat, sections, MSH 4.1 in ASCII and binary),
 * gmsh_v22.c (MSH 2.2 ASCII) and gmsh_geo.c (a .geo meshed by the Gmsh library). The same value readers serve
 * ASCII and binary sections: in a binary section of a 4.1 file (rd->binary) an int is 4 bytes, a size_t 8 and a
 * double 8, read little-endian as written, each read checked against the bytes left. Lines are counted in
 * binary data too, so every error names file:LINE as an editor or `less` shows it. */
#ifndef MICA_GMSH_READER_H
#define MICA_GMSH_READER_H

#include "geom_private.h"

enum { GMSH_TOKEN_MAX = 256, GMSH_NODES_MAX = 8 /* nodes of the largest element type read */ };

typedef struct {
  const char *path;
  const char *buf;
  size_t len, pos;
  long line;       /* line of the current position */
  long token_line; /* line where the last value started */
  const char *section;
  int binary;      /* the current section's numbers are binary (4.1 binary files: $Entities, $Nodes, $Elements) */
  GmshFilter *filter; /* gmsh_read_filtered: the nodes kept, and the elements whose nodes all are (NULL: all) */
} GmshReader;

/* Node tags as read, and the line of each, resolved to indices at the end (gmsh_resolve_nodes). */
typedef struct {
  long *tag, *line;
  long node_capacity; /* slots of tag, line, mesh->x (and mesh->node_key with a filter) */
  long *elem_tag; /* element node tags before resolution */
  long elem_capacity;
  int *elem_phys; /* MSH 2.2: each element's physical tag (0: none) */
  long elements_capacity; /* slots of the mesh's per-element arrays (and elem_phys) */
  long elements_read;     /* elements read from the $Elements section, kept or not */
  long *kept_tags;        /* a filter: the kept nodes' tags, sorted, once $Elements begins */
  long nkept_tags;
  int *groups;            /* a filter on a 2.2 file: the (dimension, physical tag) pairs of every element read */
  long ngroups, groups_capacity;
} GmshRawTags;

/* ---- errors: MICA_ERR_INPUT "file:LINE: detail" ---- */
int gmsh_fail(const GmshReader *rd, long line, const char *fmt, ...) MICA_PRINTF(3, 4);
int gmsh_fail_eof(const GmshReader *rd, const char *what);
/* The error for an element type mica does not read; higher-order types name the remedy (gmsh -order 1). */
int gmsh_fail_type(const GmshReader *rd, long line, int type);
/* The same sentence for a mesh with no file lines (a .geo meshed by the library): "what: detail". */
void gmsh_type_message(int type, char *out, size_t size);

/* ---- values (ASCII tokens, or binary in a binary section) ---- */
int gmsh_next_token(GmshReader *rd, char *tok); /* 0 at the end of the file */
int gmsh_read_word(GmshReader *rd, char *tok, const char *what);
int gmsh_read_long(GmshReader *rd, const char *what, long *v);  /* binary: a size_t */
int gmsh_read_count(GmshReader *rd, const char *what, long *v); /* a long no larger than the bytes left */
int gmsh_read_int(GmshReader *rd, const char *what, int *v);    /* binary: an int */
int gmsh_read_double(GmshReader *rd, const char *what, double *v);
/* Grows raw->elem_tag to hold `need` node tags. */
int gmsh_reserve_element_nodes(GmshRawTags *raw, long need);
/* The node arrays for n nodes (coordinates, tags and their lines; with a filter, grown as nodes are kept), replacing
 * any earlier ones: a file may list its $Nodes section more than once. */
int gmsh_nodes_alloc(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long n);
/* Node `key` (its position in $Nodes) with its tag, line and coordinates, appended unless the filter drops it. */
int gmsh_node_add(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long tag, long line, const double x[3],
                  long key);
/* The per-element arrays for n elements (with a filter: grown as elements are kept). */
int gmsh_elements_alloc(const GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw, long n);
/* Room for one more element. */
int gmsh_element_reserve(GmshMesh *mesh, GmshRawTags *raw);
/* Whether an element of `type` with node tags tags[k] is kept (a filter keeps it if it keeps all its nodes); counts
 * it and its dimension (filter->max_dim). */
int gmsh_element_kept(GmshReader *rd, GmshRawTags *raw, int type, const long *tags, int k);

/* ---- MSH 2.2 ASCII (gmsh_v22.c) ---- */
int gmsh_v22_nodes(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw);
int gmsh_v22_elements(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw);
/* After the file: merges the copies of an element listed once per physical group, and gives each element
 * the entity of its set of physical groups, so that mesh.c sees what a 4.1 file's $Entities would say. With a
 * filter, every group of the file gets an entity, so that a part names every set as the whole mesh does. */
int gmsh_v22_entities(GmshMesh *mesh, GmshRawTags *raw, int filtered);

/* ---- shared by every source ---- */
/* Allocates entity tables for count[d] entities of each dimension (replacing any earlier ones). */
int gmsh_entities_alloc(GmshMesh *mesh, const long count[4]);
/* Appends entity (d, tag), with no physical tags yet; then gmsh_entity_push adds them to it. *capacity is the
 * caller's count of the slots of entity_phys[d], 0 after gmsh_entities_alloc. */
void gmsh_entity_begin(GmshMesh *mesh, int d, int tag);
int gmsh_entity_push(GmshMesh *mesh, int d, long *capacity, int phys);
/* Node tags → indices: repeated tags and elements naming undefined nodes are errors at their lines. */
int gmsh_resolve_nodes(const GmshReader *rd, GmshMesh *mesh, const GmshRawTags *raw);
/* Reads a whole file into a NUL-terminated buffer. */
int gmsh_load_file(const char *path, const char *what, char **buf, size_t *len);

#endif
