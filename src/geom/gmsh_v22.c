/* MSH 2.2 ASCII (docs/theory.md §geometry, "Gmsh meshes"): $Nodes is "n" then "tag x y z" lines; $Elements is
 * "n" then "tag type ntags tag... node..." lines, whose first tag is the element's physical group (0: none) and
 * the second its elementary entity. An element in several physical groups is written once per group; mica
 * merges the copies (same type, same nodes in the same order) and keeps the first one's tag and line. Each
 * element then gets a pseudo-entity, one per distinct set of physical groups in each dimension, so that mesh.c
 * finds an element's groups as it does in a 4.1 file, exactly per element whatever the elementary tags say.
 */
#include <stdlib.h>
#include <string.h>

#include "gmsh_reader.h"


int gmsh_v22_nodes(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  long n;
  MICA_CALL(gmsh_read_count(rd, "the number of nodes", &n));
  MICA_CALL(gmsh_nodes_alloc(rd, mesh, raw, n));
  for (long i = 0; i < n; i++) {
    long tag;
    double x[3];
    MICA_CALL(gmsh_read_long(rd, "a node tag", &tag));
    if (tag < 1) return gmsh_fail(rd, rd->token_line, "node tag %ld must be positive", tag);
    const long line = rd->token_line;
    for (int d = 0; d < 3; d++) MICA_CALL(gmsh_read_double(rd, "a node coordinate", &x[d]));
    MICA_CALL(gmsh_node_add(rd, mesh, raw, tag, line, x, i));
  }
  return MICA_SUCCESS;
}

/* A filter: the (dimension, physical tag) pairs of every element read, kept or not (gmsh_v22_entities names them). */
static int note_group(GmshRawTags *raw, int dim, int phys) {
  for (long g = 0; g < raw->ngroups; g++)
    if (raw->groups[2 * g] == dim && raw->groups[2 * g + 1] == phys) return MICA_SUCCESS;
  if (raw->ngroups == raw->groups_capacity) {
    raw->groups_capacity = 2 * raw->groups_capacity + 8;
    MICA_CALL(MICA_REALLOC(raw->groups, 2 * raw->groups_capacity));
  }
  raw->groups[2 * raw->ngroups] = dim, raw->groups[2 * raw->ngroups + 1] = phys;
  raw->ngroups++;
  return MICA_SUCCESS;
}

/* One element line; its elementary tag goes to entity_tag until gmsh_v22_entities replaces it. */
static int read_element(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  int type, tags[2] = {0, 0};
  long ntags, tag, nodes[GMSH_NODES_MAX];
  MICA_CALL(gmsh_read_long(rd, "an element tag", &tag));
  const long line = rd->token_line;
  MICA_CALL(gmsh_read_int(rd, "an element type", &type));
  const int k = gmsh_element_nodes(type);
  if (k == 0) return gmsh_fail_type(rd, rd->token_line, type);
  MICA_CALL(gmsh_read_count(rd, "the number of tags", &ntags));
  for (long t = 0; t < ntags; t++) {
    int v;
    MICA_CALL(gmsh_read_int(rd, "an element tag (physical, elementary, partitions)", &v));
    if (t < 2) tags[t] = v;
  }
  for (int j = 0; j < k; j++) MICA_CALL(gmsh_read_long(rd, "an element's node tag", &nodes[j]));
  if (rd->filter && tags[0] != 0) MICA_CALL(note_group(raw, gmsh_element_dim(type), tags[0]));
  if (!gmsh_element_kept(rd, raw, type, nodes, k)) return MICA_SUCCESS;
  MICA_CALL(gmsh_element_reserve(mesh, raw));
  const long e = mesh->nelements, start = mesh->node_start[e];
  mesh->tag[e] = tag, mesh->line[e] = line;
  MICA_CALL(gmsh_reserve_element_nodes(raw, start + k));
  memcpy(&raw->elem_tag[start], nodes, sizeof(long) * (size_t)k);
  mesh->type[e] = type, mesh->entity_dim[e] = gmsh_element_dim(type), mesh->entity_tag[e] = tags[1];
  raw->elem_phys[e] = tags[0];
  mesh->node_start[e + 1] = start + k;
  mesh->nelements++;
  return MICA_SUCCESS;
}

int gmsh_v22_elements(GmshReader *rd, GmshMesh *mesh, GmshRawTags *raw) {
  long n;
  MICA_CALL(gmsh_read_count(rd, "the number of elements", &n));
  MICA_CALL(gmsh_elements_alloc(rd, mesh, raw, n));
  for (long i = 0; i < n; i++) MICA_CALL(read_element(rd, mesh, raw));
  return MICA_SUCCESS;
}

/* ---- copies of one element: same type, same node tags in the same order ---- */

typedef struct {
  int type, n;
  long nodes[GMSH_NODES_MAX];
  long index;
} ElementKey;

static int compare_element(const void *a, const void *b) {
  const ElementKey *x = a, *y = b;
  if (x->type != y->type) return (x->type > y->type) - (x->type < y->type);
  for (int i = 0; i < x->n; i++)
    if (x->nodes[i] != y->nodes[i]) return (x->nodes[i] > y->nodes[i]) - (x->nodes[i] < y->nodes[i]);
  return (x->index > y->index) - (x->index < y->index);
}

/* keeper[e]: the first element (in file order) of which e is a copy, e itself for a first one. */
static int find_copies(const GmshMesh *mesh, const GmshRawTags *raw, long *keeper) {
  ElementKey *keys = NULL;
  MICA_CALL(MICA_CALLOC(keys, mesh->nelements));
  for (long e = 0; e < mesh->nelements; e++) {
    ElementKey *k = &keys[e];
    k->type = mesh->type[e], k->n = (int)(mesh->node_start[e + 1] - mesh->node_start[e]), k->index = e;
    memcpy(k->nodes, &raw->elem_tag[mesh->node_start[e]], (size_t)k->n * sizeof k->nodes[0]);
  }
  qsort(keys, (size_t)mesh->nelements, sizeof *keys, compare_element);
  for (long i = 0, first = 0; i < mesh->nelements; i++) { /* a group is sorted by index: its first keeps */
    const int same = i > 0 && keys[i].type == keys[first].type &&
                     memcmp(keys[i].nodes, keys[first].nodes, (size_t)keys[i].n * sizeof keys[i].nodes[0]) == 0;
    if (!same) first = i;
    keeper[keys[i].index] = keys[first].index;
  }
  MICA_FREE(keys);
  return MICA_SUCCESS;
}

/* ---- each kept element's set of physical groups, and one entity per distinct set ---- */

typedef struct {
  long keeper, phys;
} Membership;

static int compare_membership(const void *a, const void *b) {
  const Membership *x = a, *y = b;
  if (x->keeper != y->keeper) return (x->keeper > y->keeper) - (x->keeper < y->keeper);
  return (x->phys > y->phys) - (x->phys < y->phys);
}

typedef struct {
  int dim;
  const Membership *list; /* the element's groups: list[0..len) */
  long len, element;
} GroupSet;

static int compare_set(const void *a, const void *b) {
  const GroupSet *x = a, *y = b;
  if (x->dim != y->dim) return (x->dim > y->dim) - (x->dim < y->dim);
  for (long i = 0; i < x->len && i < y->len; i++) {
    const long p = x->list[i].phys, q = y->list[i].phys;
    if (p != q) return (p > q) - (p < q);
  }
  return (x->len > y->len) - (x->len < y->len);
}

/* The distinct (keeper, physical tag) pairs, sorted; *n of them. */
static int memberships(const GmshMesh *mesh, const GmshRawTags *raw, const long *keeper, Membership **m, long *n) {
  MICA_CALL(MICA_MALLOC(*m, mesh->nelements));
  long k = 0;
  for (long e = 0; e < mesh->nelements; e++)
    if (raw->elem_phys[e] != 0) (*m)[k++] = (Membership){keeper[e], raw->elem_phys[e]};
  qsort(*m, (size_t)k, sizeof **m, compare_membership);
  *n = 0;
  for (long i = 0; i < k; i++)
    if (*n == 0 || compare_membership(&(*m)[i], &(*m)[*n - 1]) != 0) (*m)[(*n)++] = (*m)[i];
  return MICA_SUCCESS;
}

/* Entities 1, 2, ... of each dimension, one per distinct set of groups; entity_tag of every kept element. */
static int make_entities(GmshMesh *mesh, const long *keeper, const Membership *m, long nm) {
  int ierr = MICA_SUCCESS;
  GroupSet *sets = NULL;
  long nsets = 0, count[4] = {0, 0, 0, 0}, capacity[4] = {0, 0, 0, 0};
  MICA_CALL(MICA_MALLOC(sets, mesh->nelements));
  for (long e = 0, j = 0; e < mesh->nelements; e++) {
    if (keeper[e] != e) continue;
    while (j < nm && m[j].keeper < e) j++;
    long len = 0;
    while (j + len < nm && m[j + len].keeper == e) len++;
    const int d = mesh->entity_dim[e] < 0 || mesh->entity_dim[e] > 3 ? 0 : mesh->entity_dim[e];
    sets[nsets++] = (GroupSet){d, &m[j], len, e};
    count[d]++;
  }
  qsort(sets, (size_t)nsets, sizeof *sets, compare_set);
  MICA_CALL_CLEANUP(gmsh_entities_alloc(mesh, count));
  for (long i = 0; i < nsets; i++) {
    const GroupSet *s = &sets[i];
    if (i == 0 || compare_set(s, &sets[i - 1]) != 0) {
      gmsh_entity_begin(mesh, s->dim, (int)mesh->nentities[s->dim] + 1);
      for (long k = 0; k < s->len; k++)
        MICA_CALL_CLEANUP(gmsh_entity_push(mesh, s->dim, &capacity[s->dim], (int)s->list[k].phys));
    }
    mesh->entity_tag[s->element] = (int)mesh->nentities[s->dim];
  }
cleanup:
  MICA_FREE(sets);
  return ierr;
}

/* Drops the copies, keeping the order of the first ones. */
static void compact(GmshMesh *mesh, GmshRawTags *raw, const long *keeper) {
  long kept = 0, conn = 0;
  for (long e = 0; e < mesh->nelements; e++) {
    if (keeper[e] != e) continue;
    const long start = mesh->node_start[e], k = mesh->node_start[e + 1] - start;
    memmove(&raw->elem_tag[conn], &raw->elem_tag[start], (size_t)k * sizeof raw->elem_tag[0]);
    mesh->type[kept] = mesh->type[e], mesh->entity_dim[kept] = mesh->entity_dim[e];
    mesh->entity_tag[kept] = mesh->entity_tag[e], mesh->tag[kept] = mesh->tag[e], mesh->line[kept] = mesh->line[e];
    mesh->node_start[kept] = conn;
    conn += k, kept++;
  }
  mesh->node_start[kept] = conn;
  mesh->nelements = kept;
}

/* An entity holding physical group `phys` alone, of no element, appended in dimension d. */
static int add_group_entity(GmshMesh *mesh, int d, int phys) {
  const long n = mesh->nentities[d], nphys = mesh->entity_phys_start[d][n];
  long capacity = nphys; /* entity_phys[d] holds exactly nphys: grown by gmsh_entity_push */
  MICA_CALL(MICA_REALLOC(mesh->entity_tags[d], n + 1));
  MICA_CALL(MICA_REALLOC(mesh->entity_phys_start[d], n + 2));
  gmsh_entity_begin(mesh, d, (int)n + 1);
  return gmsh_entity_push(mesh, d, &capacity, phys);
}

/* Every group of the file that no kept element holds gets an entity of its own. */
static int name_all_groups(GmshMesh *mesh, const GmshRawTags *raw) {
  for (long g = 0; g < raw->ngroups; g++) {
    const int d = raw->groups[2 * g] < 0 || raw->groups[2 * g] > 3 ? 0 : raw->groups[2 * g], phys = raw->groups[2 * g + 1];
    int held = 0;
    for (long k = 0; k < mesh->entity_phys_start[d][mesh->nentities[d]] && !held; k++) held = mesh->entity_phys[d][k] == phys;
    if (!held) MICA_CALL(add_group_entity(mesh, d, phys));
  }
  return MICA_SUCCESS;
}

int gmsh_v22_entities(GmshMesh *mesh, GmshRawTags *raw, int filtered) {
  int ierr = MICA_SUCCESS;
  long *keeper = NULL, nm = 0;
  Membership *m = NULL;
  MICA_CALL_CLEANUP(MICA_MALLOC(keeper, mesh->nelements + 1));
  MICA_CALL_CLEANUP(find_copies(mesh, raw, keeper));
  MICA_CALL_CLEANUP(memberships(mesh, raw, keeper, &m, &nm));
  MICA_CALL_CLEANUP(make_entities(mesh, keeper, m, nm));
  compact(mesh, raw, keeper);
  if (filtered) MICA_CALL_CLEANUP(name_all_groups(mesh, raw));
cleanup:
  MICA_FREE(keeper);
  MICA_FREE(m);
  return ierr;
}
