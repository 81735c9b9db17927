/* A .geo meshed by the Gmsh library (docs/theory.md §geometry, "Gmsh meshes"; docs/input.md, geometry.mesh).
 *
 * The library is loaded with dlopen only when a deck names a .geo: linked into mica it would cost every start
 * of mica (about 110 ms: it loads some 90 shared libraries, OpenCASCADE among them; mica starts in 9 ms), and
 * mica is started hundreds of times by its tests and studies. It stays loaded for the rest of the process
 * (its C++ and OpenCASCADE statics go at exit, not at a dlclose). The function types come from gmshc.h, the
 * header of the library's C API, so a changed signature fails to compile; the library loaded is the soname of
 * that header's version (libgmsh.so.MAJOR.MINOR), or MICA_GMSH_LIBRARY, checked to be the same version.
 *
 * One session per .geo: check the script (gmsh_geo_check.c), initialize without the user's Gmsh configuration
 * files, silence the terminal (errors come back through the session's log and name the .geo and its line),
 * open, mesh in the model's dimension (as gmsh -2 or -3 does; Mesh.MeshSizeFactor times the deck's factor),
 * copy nodes, elements and physical groups into the GmshMesh a .msh file of it would give, finalize. Gmsh
 * saves only the elements of entities in physical groups when there are any (unless Mesh.SaveAll = 1), and so
 * does this copy, so a .geo and the .msh that `gmsh -2 FILE.geo` writes give mica the same mesh. Gmsh's
 * initialization changes the process's locale and raises its stack limit; both are put back afterwards.
 */
#include <dlfcn.h>
#include <limits.h>
#include <locale.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include <gmshc.h>

#include "gmsh_reader.h"

#define STRINGIFY_(x) #x
#define STRINGIFY(x) STRINGIFY_(x)
#define GMSH_SONAME "libgmsh.so." STRINGIFY(GMSH_API_VERSION_MAJOR) "." STRINGIFY(GMSH_API_VERSION_MINOR)

enum { MESSAGE_MAX = 1024 };

typedef struct {
  __typeof__(&gmshInitialize) initialize;
  __typeof__(&gmshFinalize) finalize;
  __typeof__(&gmshOpen) open;
  __typeof__(&gmshOptionSetNumber) set_number;
  __typeof__(&gmshOptionGetNumber) get_number;
  __typeof__(&gmshModelGetDimension) dimension;
  __typeof__(&gmshModelMeshGenerate) generate;
  __typeof__(&gmshModelGetEntities) entities;
  __typeof__(&gmshModelGetPhysicalGroups) physical_groups;
  __typeof__(&gmshModelGetPhysicalName) physical_name;
  __typeof__(&gmshModelGetPhysicalGroupsForEntity) entity_groups;
  __typeof__(&gmshModelMeshGetNodes) nodes;
  __typeof__(&gmshModelMeshGetElements) elements;
  __typeof__(&gmshLoggerGetLastError) last_error;
  __typeof__(&gmshLoggerStart) logger_start;
  __typeof__(&gmshLoggerGet) logger_get;
  __typeof__(&gmshLoggerStop) logger_stop;
  __typeof__(&gmshFree) free;
  __typeof__(&gmshWrite) write;
} GmshApi;

static GmshApi api; /* loaded once per process */

/* ---- loading ---- */

static int missing_library(const char *geo, const char *name, const char *why) {
  MICA_ERROR(MICA_ERR_LIBRARY,
             "%s: meshing a .geo needs the Gmsh %d.%d library, and %s %s: install Debian's libgmsh-dev (make "
             "deps), or mesh it with gmsh (gmsh -2 FILE.geo -o FILE.msh) and name the .msh in geometry.mesh",
             geo, GMSH_API_VERSION_MAJOR, GMSH_API_VERSION_MINOR, name, why);
}

/* Gmsh 4.8's C API has no version query; its C++ GetGmshMajorVersion() and GetGmshMinorVersion() are
 * int f(void), which a C pointer may call. */
static int check_version(const char *geo, const char *name, void *handle) {
  int (*major)(void) = (int (*)(void))dlsym(handle, "_Z19GetGmshMajorVersionv");
  int (*minor)(void) = (int (*)(void))dlsym(handle, "_Z19GetGmshMinorVersionv");
  char why[128];
  if (!major || !minor) return missing_library(geo, name, "is not a Gmsh library (it has no version)");
  if (major() == GMSH_API_VERSION_MAJOR && minor() == GMSH_API_VERSION_MINOR) return MICA_SUCCESS;
  snprintf(why, sizeof why, "is Gmsh %d.%d, whose C API mica was not built with", major(), minor());
  return missing_library(geo, name, why);
}

#define LOAD(slot, symbol)                                                                  \
  do {                                                                                      \
    if (!(loaded.slot = (__typeof__(&symbol))dlsym(handle, #symbol)))                       \
      return missing_library(geo, name, "lacks " #symbol);                                  \
  } while (0)

static int load_api(const char *geo) {
  if (api.initialize) return MICA_SUCCESS;
  const char *name = getenv("MICA_GMSH_LIBRARY");
  if (!name || !name[0]) name = GMSH_SONAME;
  void *handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    char why[MESSAGE_MAX];
    snprintf(why, sizeof why, "cannot be loaded (%s)", dlerror());
    return missing_library(geo, name, why);
  }
  MICA_CALL(check_version(geo, name, handle));
  GmshApi loaded;
  LOAD(initialize, gmshInitialize);
  LOAD(finalize, gmshFinalize);
  LOAD(open, gmshOpen);
  LOAD(set_number, gmshOptionSetNumber);
  LOAD(get_number, gmshOptionGetNumber);
  LOAD(dimension, gmshModelGetDimension);
  LOAD(generate, gmshModelMeshGenerate);
  LOAD(entities, gmshModelGetEntities);
  LOAD(physical_groups, gmshModelGetPhysicalGroups);
  LOAD(physical_name, gmshModelGetPhysicalName);
  LOAD(entity_groups, gmshModelGetPhysicalGroupsForEntity);
  LOAD(nodes, gmshModelMeshGetNodes);
  LOAD(elements, gmshModelMeshGetElements);
  LOAD(last_error, gmshLoggerGetLastError);
  LOAD(logger_start, gmshLoggerStart);
  LOAD(logger_get, gmshLoggerGet);
  LOAD(logger_stop, gmshLoggerStop);
  LOAD(free, gmshFree);
  LOAD(write, gmshWrite);
  api = loaded;
  return MICA_SUCCESS;
}

/* ---- errors ---- */

/* A message of the library as mica's error: "'FILE', line N: what" becomes "FILE:N: what (Gmsh, ...)". */
static int gmsh_message_error(const char *geo, const char *doing, const char *m) {
  if (!m || !m[0]) m = "Gmsh gave no message";
  const char *close = m[0] == '\'' ? strstr(m + 1, "', line ") : NULL;
  char *end = NULL;
  const long line = close ? strtol(close + 8, &end, 10) : 0;
  if (close && end && end[0] == ':' && line > 0)
    return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%.*s:%ld:%s (Gmsh, %s %s)",
                          (int)(close - m - 1), m + 1, line, end + 1, doing, geo);
  return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s: Gmsh failed %s it: %s", geo, doing, m);
}

/* A call of the API that failed: its last error. */
static int library_error(const char *geo, const char *doing) {
  char *msg = NULL;
  int gierr = 0;
  api.last_error(&msg, &gierr);
  const int ierr = gmsh_message_error(geo, doing, gierr ? NULL : msg);
  if (msg) api.free(msg);
  return ierr;
}

/* General.AbortOnError = 0 lets Gmsh finish a file after an error (an exception out of its parser would leave
 * the parser's input behind for the next .geo of the process), so errors are found in the session's log: the
 * first "Error: " line, the cause, fails the step. */
static int check_log(const char *geo, const char *doing) {
  char **log = NULL;
  size_t n = 0;
  int gierr = 0, ierr = MICA_SUCCESS;
  api.logger_get(&log, &n, &gierr);
  if (gierr) return library_error(geo, doing);
  for (size_t i = 0; i < n && !ierr; i++)
    if (!strncmp(log[i], "Error: ", 7)) ierr = gmsh_message_error(geo, doing, log[i] + 7);
  for (size_t i = 0; i < n; i++) api.free(log[i]);
  if (log) api.free(log);
  return ierr;
}

#define GMSH_CALL(geo, doing, call)                 \
  do {                                              \
    int gmsh_ierr_ = 0;                             \
    call;                                           \
    if (gmsh_ierr_) return library_error(geo, doing); \
  } while (0)

/* ---- the model → GmshMesh ---- */

static int copy_physical_names(const char *geo, GmshMesh *mesh) {
  int *dim_tags = NULL;
  size_t n = 0;
  GMSH_CALL(geo, "reading the physical groups of", api.physical_groups(&dim_tags, &n, -1, &gmsh_ierr_));
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_CALLOC(mesh->physicals, n / 2));
  for (size_t i = 0; i + 1 < n; i += 2) {
    char *name = NULL;
    int gierr = 0;
    api.physical_name(dim_tags[i], dim_tags[i + 1], &name, &gierr);
    const size_t len = !gierr && name ? strlen(name) : 0;
    GmshPhysical *p = &mesh->physicals[mesh->nphysicals];
    if (len >= sizeof p->name) {
      ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT,
                            "%s: the physical group name '%.40s...' is longer than %zu characters", geo, name,
                            sizeof p->name - 1);
    } else if (len > 0) { /* unnamed groups are named by their tag, as in a .msh file */
      p->dim = dim_tags[i], p->tag = dim_tags[i + 1];
      memcpy(p->name, name, len + 1);
      mesh->nphysicals++;
    }
    if (name) api.free(name);
    if (ierr) goto cleanup;
  }
cleanup:
  api.free(dim_tags);
  return ierr;
}

/* Every entity with its physical groups; *kept[i] says whether entity i's elements are kept (Gmsh's rule). */
static int copy_entities(const char *geo, GmshMesh *mesh, int **dim_tags, size_t *n, char **kept) {
  double save_all = 0;
  int ierr = MICA_SUCCESS;
  long count[4] = {0, 0, 0, 0}, capacity[4] = {0, 0, 0, 0};
  GMSH_CALL(geo, "reading the option Mesh.SaveAll of", api.get_number("Mesh.SaveAll", &save_all, &gmsh_ierr_));
  GMSH_CALL(geo, "reading the entities of", api.entities(dim_tags, n, -1, &gmsh_ierr_));
  for (size_t i = 0; i + 1 < *n; i += 2) count[(*dim_tags)[i] & 3]++;
  MICA_CALL(gmsh_entities_alloc(mesh, count));
  MICA_CALL(MICA_CALLOC(*kept, *n / 2 + 1));
  for (size_t i = 0; i + 1 < *n; i += 2) {
    const int d = (*dim_tags)[i] & 3;
    int *phys = NULL;
    size_t np = 0;
    GMSH_CALL(geo, "reading the physical groups of",
              api.entity_groups((*dim_tags)[i], (*dim_tags)[i + 1], &phys, &np, &gmsh_ierr_));
    gmsh_entity_begin(mesh, d, (*dim_tags)[i + 1]);
    for (size_t k = 0; k < np && !ierr; k++) ierr = gmsh_entity_push(mesh, d, &capacity[d], phys[k]);
    (*kept)[i / 2] = np > 0 || mesh->nphysicals == 0 || save_all != 0;
    api.free(phys);
    MICA_CALL(ierr);
  }
  return MICA_SUCCESS;
}

static int copy_nodes(const char *geo, GmshMesh *mesh, GmshRawTags *raw) {
  size_t *tags = NULL, ntags = 0, ncoord = 0, nparam = 0;
  double *coord = NULL, *param = NULL;
  int ierr = MICA_SUCCESS;
  GMSH_CALL(geo, "reading the nodes of",
            api.nodes(&tags, &ntags, &coord, &ncoord, &param, &nparam, -1, -1, 0, 0, &gmsh_ierr_));
  if (ncoord != 3 * ntags) {
    ierr = mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_LIBRARY, "%s: Gmsh gave %zu coordinates for %zu "
                          "nodes", geo, ncoord, ntags);
    goto cleanup;
  }
  MICA_CALL_CLEANUP(MICA_MALLOC(mesh->x, ncoord));
  MICA_CALL_CLEANUP(MICA_MALLOC(raw->tag, ntags));
  MICA_CALL_CLEANUP(MICA_CALLOC(raw->line, ntags));
  if (ncoord) memcpy(mesh->x, coord, ncoord * sizeof *coord);
  for (size_t i = 0; i < ntags; i++) raw->tag[i] = tags[i] > (size_t)LONG_MAX ? -1 : (long)tags[i];
  mesh->nnodes = (long)ntags;
cleanup:
  api.free(tags);
  api.free(coord);
  api.free(param);
  return ierr;
}

/* Room for `more` elements and `nodes` more node tags. */
static int grow_elements(GmshMesh *mesh, GmshRawTags *raw, long *capacity, long more, long nodes) {
  if (!mesh->node_start) MICA_CALL(MICA_CALLOC(mesh->node_start, 1));
  MICA_CALL(gmsh_reserve_element_nodes(raw, mesh->node_start[mesh->nelements] + nodes));
  if (mesh->nelements + more <= *capacity) return MICA_SUCCESS;
  *capacity = 2 * *capacity + more;
  MICA_CALL(MICA_REALLOC(mesh->type, *capacity));
  MICA_CALL(MICA_REALLOC(mesh->entity_dim, *capacity));
  MICA_CALL(MICA_REALLOC(mesh->entity_tag, *capacity));
  MICA_CALL(MICA_REALLOC(mesh->tag, *capacity));
  MICA_CALL(MICA_REALLOC(mesh->line, *capacity));
  MICA_CALL(MICA_REALLOC(mesh->node_start, *capacity + 1));
  return MICA_SUCCESS;
}

/* The elements of one type in entity (dim, tag). */
static int append_block(const char *geo, GmshMesh *mesh, GmshRawTags *raw, long *capacity, const int dim_tag[2],
                        int type, const size_t *etags, size_t n, const size_t *ntags, size_t nn) {
  const int k = gmsh_element_nodes(type);
  if (k == 0) {
    char msg[MESSAGE_MAX];
    gmsh_type_message(type, msg, sizeof msg);
    MICA_ERROR(MICA_ERR_INPUT, "%s: Gmsh made elements that mica does not read: %s", geo, msg);
  }
  MICA_CHECK(nn == n * (size_t)k, MICA_ERR_LIBRARY, "%s: Gmsh gave %zu node tags for %zu elements of type %d", geo,
             nn, n, type);
  MICA_CALL(grow_elements(mesh, raw, capacity, (long)n, (long)nn));
  for (size_t i = 0; i < n; i++) {
    const long e = mesh->nelements++, start = mesh->node_start[e];
    mesh->type[e] = type, mesh->entity_dim[e] = dim_tag[0], mesh->entity_tag[e] = dim_tag[1];
    mesh->tag[e] = etags[i] > (size_t)LONG_MAX ? -1 : (long)etags[i], mesh->line[e] = 0;
    for (int j = 0; j < k; j++) {
      const size_t t = ntags[i * (size_t)k + (size_t)j];
      raw->elem_tag[start + j] = t > (size_t)LONG_MAX ? -1 : (long)t;
    }
    mesh->node_start[e + 1] = start + k;
  }
  return MICA_SUCCESS;
}

static void free_nested(size_t **v, size_t n) {
  for (size_t i = 0; v && i < n; i++) api.free(v[i]);
  api.free(v);
}

/* Entity by entity, type by type: the order of the blocks of a .msh file. */
static int copy_entity_elements(const char *geo, GmshMesh *mesh, GmshRawTags *raw, long *capacity,
                                const int dim_tag[2]) {
  int *types = NULL, ierr = MICA_SUCCESS;
  size_t ntypes = 0, **etags = NULL, *etags_n = NULL, etags_nn = 0, **ntags = NULL, *ntags_n = NULL, ntags_nn = 0;
  GMSH_CALL(geo, "reading the elements of",
            api.elements(&types, &ntypes, &etags, &etags_n, &etags_nn, &ntags, &ntags_n, &ntags_nn, dim_tag[0],
                         dim_tag[1], &gmsh_ierr_));
  for (size_t t = 0; t < ntypes && t < etags_nn && t < ntags_nn; t++)
    MICA_CALL_CLEANUP(append_block(geo, mesh, raw, capacity, dim_tag, types[t], etags[t], etags_n[t], ntags[t],
                                   ntags_n[t]));
cleanup:
  api.free(types);
  free_nested(etags, etags_nn);
  api.free(etags_n);
  free_nested(ntags, ntags_nn);
  api.free(ntags_n);
  return ierr;
}

static int copy_model(const char *geo, GmshMesh *mesh, GmshRawTags *raw) {
  int ierr = MICA_SUCCESS, *dim_tags = NULL;
  size_t n = 0;
  char *kept = NULL;
  long capacity = 0;
  MICA_CALL(copy_physical_names(geo, mesh));
  MICA_CALL_CLEANUP(copy_entities(geo, mesh, &dim_tags, &n, &kept));
  MICA_CALL_CLEANUP(copy_nodes(geo, mesh, raw));
  MICA_CALL_CLEANUP(grow_elements(mesh, raw, &capacity, 0, 0));
  for (size_t i = 0; i + 1 < n; i += 2)
    if (kept[i / 2]) MICA_CALL_CLEANUP(copy_entity_elements(geo, mesh, raw, &capacity, &dim_tags[i]));
cleanup:
  if (dim_tags) api.free(dim_tags);
  MICA_FREE(kept);
  return ierr;
}

/* ---- one session ---- */

/* The meshed model as a binary MSH 4.1 file (Gmsh's own writer, with its rule of the saved entities). */
static int write_model(const char *geo, const char *msh) {
  GMSH_CALL(geo, "writing the mesh of", api.set_number("Mesh.MshFileVersion", 4.1, &gmsh_ierr_));
  GMSH_CALL(geo, "writing the mesh of", api.set_number("Mesh.Binary", 1, &gmsh_ierr_));
  GMSH_CALL(geo, "writing the mesh of", api.write(msh, &gmsh_ierr_));
  return check_log(geo, "writing the mesh of");
}

/* Opens and meshes the .geo in the current session, then copies the model into mesh, or writes it to msh. */
static int mesh_model(const char *geo, double size_factor, const char *msh, GmshMesh *mesh, GmshRawTags *raw) {
  int dim = 0;
  double factor = 1;
  GMSH_CALL(geo, "reading", api.open(geo, &gmsh_ierr_));
  MICA_CALL(check_log(geo, "reading"));
  GMSH_CALL(geo, "reading", dim = api.dimension(&gmsh_ierr_));
  MICA_CHECK(dim >= 2, MICA_ERR_INPUT, "%s: the geometry has no surface or volume (its dimension is %d)", geo, dim);
  if (size_factor > 0) {
    GMSH_CALL(geo, "setting the mesh size factor of", api.get_number("Mesh.MeshSizeFactor", &factor, &gmsh_ierr_));
    GMSH_CALL(geo, "setting the mesh size factor of",
              api.set_number("Mesh.MeshSizeFactor", factor * size_factor, &gmsh_ierr_));
  }
  GMSH_CALL(geo, "meshing", api.generate(dim, &gmsh_ierr_));
  MICA_CALL(check_log(geo, "meshing"));
  return msh ? write_model(geo, msh) : copy_model(geo, mesh, raw);
}

typedef struct {
  char *locale;
  struct rlimit stack;
  int have_stack;
} ProcessState;

static int save_state(ProcessState *st) {
  const char *locale = setlocale(LC_ALL, NULL);
  const size_t n = locale ? strlen(locale) : 0;
  st->locale = NULL;
  if (locale) {
    MICA_CALL(MICA_MALLOC(st->locale, n + 1));
    memcpy(st->locale, locale, n + 1);
  }
  st->have_stack = getrlimit(RLIMIT_STACK, &st->stack) == 0;
  return MICA_SUCCESS;
}

static void restore_state(ProcessState *st) {
  if (st->locale) setlocale(LC_ALL, st->locale);
  if (st->have_stack) setrlimit(RLIMIT_STACK, &st->stack);
  MICA_FREE(st->locale);
}

static long sessions; /* of this process, for gmsh_geo_sessions */

static int session(const char *geo, double size_factor, const char *msh, GmshMesh *mesh, GmshRawTags *raw) {
  int ierr = MICA_SUCCESS, gierr = 0;
  ProcessState st;
  MICA_CALL(save_state(&st));
  sessions++;
  api.initialize(0, NULL, 0, &gierr); /* 0: not the user's gmshrc and gmsh-options files */
  if (gierr) {
    ierr = library_error(geo, "starting for");
    restore_state(&st);
    return ierr;
  }
  api.set_number("General.Terminal", 0, &gierr);
  api.set_number("General.Verbosity", 2, &gierr); /* errors and warnings */
  api.set_number("General.AbortOnError", 0, &gierr);
  api.logger_start(&gierr);
  ierr = gierr ? library_error(geo, "starting for") : mesh_model(geo, size_factor, msh, mesh, raw);
  api.logger_stop(&gierr);
  api.finalize(&gierr);
  restore_state(&st);
  return ierr;
}

int gmsh_geo_mesh(const char *path, double size_factor, GmshMesh *mesh) {
  int ierr = MICA_SUCCESS;
  GmshRawTags raw = {0};
  const GmshReader rd = {.path = path, .line = 0, .token_line = 0, .section = "Nodes"};
  MICA_CALL(gmsh_geo_check(path));
  MICA_CALL(load_api(path));
  MICA_CALL_CLEANUP(session(path, size_factor, NULL, mesh, &raw));
  MICA_CALL_CLEANUP(gmsh_resolve_nodes(&rd, mesh, &raw));
cleanup:
  MICA_FREE(raw.tag);
  MICA_FREE(raw.line);
  MICA_FREE(raw.elem_tag);
  return ierr;
}

int gmsh_geo_write(const char *path, double size_factor, const char *msh) {
  MICA_CALL(gmsh_geo_check(path));
  MICA_CALL(load_api(path));
  return session(path, size_factor, msh, NULL, NULL);
}

long gmsh_geo_sessions(void) { return sessions; }
