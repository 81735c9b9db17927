/* VTU and PVD output (src/io/vtk.c), checked without VTK: the XML header is parsed by hand, every
 * DataArray's offset must land on its block in the appended section, each block's UInt64 byte count must
 * equal points × components × size, and the bytes must be the data given (2-D points padded with z = 0,
 * vertex cells, or given cells: connectivity, end offsets, types). Non-finite values and bad cells are refused
 * and leave no file, temporary or final. Component names become ComponentName attributes; a PVD lists its
 * parts per step. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mica/vtk.h"

/* ---- Fixture: a fresh directory under /tmp --------------------------------------------------------- */

typedef struct {
  char dir[64];
  char path[128];
} Scratch;

static int scratch_setup(void **state) {
  Scratch *s = calloc(1, sizeof *s);
  if (!s) return -1;
  strcpy(s->dir, "/tmp/mica-test-vtk-XXXXXX");
  if (!mkdtemp(s->dir)) return -1;
  *state = s;
  return 0;
}

static int count_entries(const char *dir) {
  DIR *d = opendir(dir);
  int count = 0;
  for (struct dirent *e; d && (e = readdir(d));)
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) count++;
  if (d) closedir(d);
  return count;
}

static int scratch_teardown(void **state) {
  Scratch *s = *state;
  DIR *d = opendir(s->dir);
  for (struct dirent *e; d && (e = readdir(d));) {
    char path[sizeof s->dir + 258];
    snprintf(path, sizeof path, "%s/%s", s->dir, e->d_name);
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) unlink(path);
  }
  if (d) closedir(d);
  rmdir(s->dir);
  free(s);
  return 0;
}

static char *read_all(const char *path, long *size) {
  FILE *fp = fopen(path, "rb");
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  *size = ftell(fp);
  rewind(fp);
  char *bytes = malloc((size_t)*size + 1);
  assert_non_null(bytes);
  assert_int_equal(fread(bytes, 1, (size_t)*size, fp), (size_t)*size);
  bytes[*size] = '\0'; /* the XML part can be searched as a string; binary NULs end it early, harmlessly */
  fclose(fp);
  return bytes;
}

/* ---- A minimal reader of the appended layout --------------------------------------------------------- */

typedef struct {
  char type[16], name[32];
  int ncomp;
  uint64_t offset;
} ArrayInfo;

/* Value of attribute `key` inside the element text [begin, end), or NULL. */
static const char *attribute(const char *begin, const char *end, const char *key, char *value, size_t size) {
  char pattern[48];
  snprintf(pattern, sizeof pattern, " %s=\"", key);
  const char *at = strstr(begin, pattern);
  if (!at || at >= end) return NULL;
  at += strlen(pattern);
  const char *close = strchr(at, '"');
  size_t length = (size_t)(close - at) < size - 1 ? (size_t)(close - at) : size - 1;
  memcpy(value, at, length);
  value[length] = '\0';
  return value;
}

/* The DataArray elements in file order (at most max). */
static int parse_arrays(const char *xml, const char *xml_end, ArrayInfo *arrays, int max) {
  int count = 0;
  for (const char *at = strstr(xml, "<DataArray"); at && at < xml_end && count < max;
       at = strstr(at + 1, "<DataArray")) {
    const char *end = strchr(at, '>');
    ArrayInfo *a = &arrays[count++];
    char text[32];
    assert_non_null(attribute(at, end, "type", a->type, sizeof a->type));
    if (!attribute(at, end, "Name", a->name, sizeof a->name)) a->name[0] = '\0';
    a->ncomp = attribute(at, end, "NumberOfComponents", text, sizeof text) ? atoi(text) : 1;
    assert_non_null(attribute(at, end, "format", text, sizeof text));
    assert_string_equal(text, "appended");
    assert_non_null(attribute(at, end, "offset", text, sizeof text));
    a->offset = strtoull(text, NULL, 10);
  }
  return count;
}

static size_t type_size(const char *type) {
  if (!strcmp(type, "Float64") || !strcmp(type, "Int64")) return 8;
  if (!strcmp(type, "UInt8")) return 1;
  fail_msg("unexpected type %s", type);
  return 0;
}

/* ---- Tests -------------------------------------------------------------------------------------------- */

enum { NPOINTS = 7 };

static void make_data(double *x2, double *scalar, double *vector, double *tensor) {
  for (int i = 0; i < NPOINTS; i++) {
    x2[2 * i] = 0.5 * i, x2[2 * i + 1] = -1.0 / (i + 1);
    scalar[i] = i * i - 3.25;
    for (int c = 0; c < 3; c++) vector[3 * i + c] = c < 2 ? 10.0 * i + c : 0.0;
    for (int c = 0; c < 9; c++) tensor[9 * i + c] = 100.0 * i + c + 0.125;
  }
}

static void test_vtu_layout(void **state) {
  Scratch *s = *state;
  double x2[2 * NPOINTS], scalar[NPOINTS], vector[3 * NPOINTS], tensor[9 * NPOINTS];
  make_data(x2, scalar, vector, tensor);
  const MicaVtkField fields[3] = {
      {"damage", 1, scalar, NULL}, {"displacement", 3, vector, NULL}, {"stress", 9, tensor, NULL}};
  snprintf(s->path, sizeof s->path, "%s/step.vtu", s->dir);
  assert_int_equal(mica_vtu_write(s->path, 2, NPOINTS, x2, 3, fields), MICA_SUCCESS);
  assert_int_equal(count_entries(s->dir), 1); /* no temporary file left */

  long size;
  char *bytes = read_all(s->path, &size);
  assert_true(strncmp(bytes, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\"", 67) == 0);
  assert_non_null(strstr(bytes, "byte_order=\"LittleEndian\""));
  assert_non_null(strstr(bytes, "header_type=\"UInt64\""));
  assert_non_null(strstr(bytes, "NumberOfPoints=\"7\" NumberOfCells=\"7\""));
  const char *appended = strstr(bytes, "<AppendedData encoding=\"raw\">");
  assert_non_null(appended);
  const char *underscore = strchr(appended, '_');
  assert_non_null(underscore);
  const unsigned char *data = (const unsigned char *)underscore + 1;

  ArrayInfo arrays[8];
  int narrays = parse_arrays(bytes, appended, arrays, 8);
  assert_int_equal(narrays, 7); /* 3 fields, points, connectivity, offsets, types */
  const double *expected_values[3] = {scalar, vector, tensor};
  uint64_t running = 0;
  for (int k = 0; k < narrays; k++) {
    uint64_t block_bytes;
    assert_int_equal(arrays[k].offset, running);
    memcpy(&block_bytes, data + arrays[k].offset, sizeof block_bytes);
    assert_int_equal(block_bytes, (uint64_t)NPOINTS * (uint64_t)arrays[k].ncomp * type_size(arrays[k].type));
    const unsigned char *block = data + arrays[k].offset + 8;
    if (k < 3) {
      assert_string_equal(arrays[k].name, fields[k].name);
      assert_int_equal(arrays[k].ncomp, fields[k].ncomp);
      assert_memory_equal(block, expected_values[k], block_bytes);
    } else if (k == 3) { /* points, z = 0 */
      assert_int_equal(arrays[k].ncomp, 3);
      for (int i = 0; i < NPOINTS; i++) {
        double p[3];
        memcpy(p, block + 24 * i, sizeof p);
        assert_true(p[0] == x2[2 * i] && p[1] == x2[2 * i + 1] && p[2] == 0.0);
      }
    } else if (k < 6) { /* connectivity 0..n-1, offsets 1..n */
      for (int i = 0; i < NPOINTS; i++) {
        int64_t v;
        memcpy(&v, block + 8 * i, sizeof v);
        assert_int_equal(v, i + (k == 5));
      }
    } else {
      for (int i = 0; i < NPOINTS; i++) assert_int_equal(block[i], 1); /* VTK_VERTEX */
    }
    running += 8 + block_bytes;
  }
  assert_string_equal(arrays[4].name, "connectivity");
  assert_string_equal(arrays[5].name, "offsets");
  assert_string_equal(arrays[6].name, "types");
  /* the closing tags follow the last block directly */
  const char *tail = (const char *)data + running;
  assert_int_equal(tail - bytes + 30, size);
  assert_memory_equal(tail, "\n  </AppendedData>\n</VTKFile>\n", 30);
  free(bytes);
}

static void test_vtu_3d_and_empty(void **state) {
  Scratch *s = *state;
  const double x3[6] = {1, 2, 3, 4, 5, 6};
  snprintf(s->path, sizeof s->path, "%s/three.vtu", s->dir);
  assert_int_equal(mica_vtu_write(s->path, 3, 2, x3, 0, NULL), MICA_SUCCESS);
  long size;
  char *bytes = read_all(s->path, &size);
  const char *underscore = strchr(strstr(bytes, "<AppendedData"), '_');
  ArrayInfo arrays[4];
  assert_int_equal(parse_arrays(bytes, underscore, arrays, 4), 4);
  assert_memory_equal(underscore + 1 + arrays[0].offset + 8, x3, sizeof x3);
  free(bytes);
  /* no points at all: a valid file with empty blocks */
  snprintf(s->path, sizeof s->path, "%s/empty.vtu", s->dir);
  assert_int_equal(mica_vtu_write(s->path, 3, 0, NULL, 0, NULL), MICA_SUCCESS);
  bytes = read_all(s->path, &size);
  assert_non_null(strstr(bytes, "NumberOfPoints=\"0\""));
  free(bytes);
}

static void test_vtu_refuses_non_finite(void **state) {
  Scratch *s = *state;
  double x2[2 * NPOINTS], scalar[NPOINTS], vector[3 * NPOINTS], tensor[9 * NPOINTS];
  make_data(x2, scalar, vector, tensor);
  vector[3 * 4 + 1] = NAN;
  const MicaVtkField fields[2] = {{"damage", 1, scalar, NULL}, {"displacement", 3, vector, NULL}};
  snprintf(s->path, sizeof s->path, "%s/bad.vtu", s->dir);
  assert_int_equal(mica_vtu_write(s->path, 2, NPOINTS, x2, 2, fields), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "displacement"));
  x2[3] = INFINITY;
  assert_int_equal(mica_vtu_write(s->path, 2, NPOINTS, x2, 1, fields), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "points"));
  assert_int_equal(count_entries(s->dir), 0); /* neither the file nor a temporary one */
  assert_int_equal(mica_vtu_write(s->path, 4, NPOINTS, x2, 1, fields), MICA_ERR_ARGUMENT);
  mica_error_clear();
}

static void test_pvd(void **state) {
  Scratch *s = *state;
  const double times[3] = {0.0, 0.1, 2.5e-3};
  const char *const files[3] = {"step-0000.vtu", "step-0001.vtu", "a&b.vtu"};
  snprintf(s->path, sizeof s->path, "%s/run.pvd", s->dir);
  assert_int_equal(mica_pvd_write(s->path, 3, times, files), MICA_SUCCESS);
  long size;
  char *text = read_all(s->path, &size);
  assert_non_null(strstr(text, "<VTKFile type=\"Collection\" version=\"0.1\""));
  assert_non_null(strstr(text, "<DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"step-0000.vtu\"/>"));
  assert_non_null(strstr(text, "timestep=\"0.1\""));
  assert_non_null(strstr(text, "timestep=\"0.0025\""));
  assert_non_null(strstr(text, "file=\"a&amp;b.vtu\""));
  assert_non_null(strstr(text, "</Collection>\n</VTKFile>\n"));
  free(text);
  const double bad_times[1] = {NAN};
  snprintf(s->path, sizeof s->path, "%s/bad.pvd", s->dir);
  assert_int_equal(mica_pvd_write(s->path, 1, bad_times, files), MICA_ERR_NUMERIC);
  assert_int_equal(count_entries(s->dir), 1);
  mica_error_clear();
}

/* Two quadrilaterals sharing an edge and a triangle: 7 points, cells of 4, 4, 3 nodes. */
enum { MESH_POINTS = 7, MESH_CELLS = 3 };
static const double mesh_x[2 * MESH_POINTS] = {0, 0, 1, 0, 2, 0, 0, 1, 1, 1, 2, 1, 1, 2};
static const long mesh_offsets[MESH_CELLS + 1] = {0, 4, 8, 11};
static const long mesh_conn[11] = {0, 1, 4, 3, 1, 2, 5, 4, 3, 4, 6};
static const unsigned char mesh_types[MESH_CELLS] = {9, 9, 5};

static void test_vtu_cells(void **state) {
  Scratch *s = *state;
  double value[MESH_POINTS], vector[3 * MESH_POINTS];
  for (int i = 0; i < MESH_POINTS; i++) {
    value[i] = 0.5 * i - 1;
    for (int c = 0; c < 3; c++) vector[3 * i + c] = i + 0.25 * c;
  }
  static const char *const axes[3] = {"r", "z", "theta"};
  const MicaVtkField fields[2] = {{"von_mises", 1, value, NULL}, {"displacement", 3, vector, axes}};
  const MicaVtkCells cells = {MESH_CELLS, mesh_offsets, mesh_conn, mesh_types};
  snprintf(s->path, sizeof s->path, "%s/mesh.vtu", s->dir);
  assert_int_equal(mica_vtu_write_cells(s->path, 2, MESH_POINTS, mesh_x, &cells, 2, fields), MICA_SUCCESS);
  assert_int_equal(count_entries(s->dir), 1);
  long size;
  char *bytes = read_all(s->path, &size);
  assert_non_null(strstr(bytes, "NumberOfPoints=\"7\" NumberOfCells=\"3\""));
  assert_non_null(strstr(bytes, "Name=\"displacement\" NumberOfComponents=\"3\" ComponentName0=\"r\" "
                                "ComponentName1=\"z\" ComponentName2=\"theta\" format="));
  assert_null(strstr(bytes, "Name=\"von_mises\" NumberOfComponents=\"1\" ComponentName0"));
  const char *appended = strstr(bytes, "<AppendedData encoding=\"raw\">");
  const unsigned char *data = (const unsigned char *)strchr(appended, '_') + 1;
  ArrayInfo arrays[8];
  assert_int_equal(parse_arrays(bytes, appended, arrays, 8), 6); /* 2 fields, points, connectivity, offsets, types */
  const uint64_t expected_bytes[6] = {MESH_POINTS * 8, MESH_POINTS * 24, MESH_POINTS * 24, 11 * 8, MESH_CELLS * 8,
                                      MESH_CELLS};
  uint64_t running = 0;
  for (int k = 0; k < 6; k++) {
    uint64_t block_bytes;
    assert_int_equal(arrays[k].offset, running);
    memcpy(&block_bytes, data + running, sizeof block_bytes);
    assert_int_equal(block_bytes, expected_bytes[k]);
    running += 8 + block_bytes;
  }
  for (int i = 0; i < 11; i++) { /* connectivity as given */
    int64_t v;
    memcpy(&v, data + arrays[3].offset + 8 + 8 * i, sizeof v);
    assert_int_equal(v, mesh_conn[i]);
  }
  for (int c = 0; c < MESH_CELLS; c++) { /* VTK's offsets: where each cell ends */
    int64_t v;
    memcpy(&v, data + arrays[4].offset + 8 + 8 * c, sizeof v);
    assert_int_equal(v, mesh_offsets[c + 1]);
    assert_int_equal(data[arrays[5].offset + 8 + c], mesh_types[c]);
  }
  assert_memory_equal(data + running, "\n  </AppendedData>\n</VTKFile>\n", 30);
  free(bytes);
}

static void test_vtu_refuses_bad_cells(void **state) {
  Scratch *s = *state;
  double value[MESH_POINTS] = {0};
  const MicaVtkField fields[1] = {{"v", 1, value, NULL}};
  long conn[11];
  unsigned char types[MESH_CELLS];
  memcpy(conn, mesh_conn, sizeof conn);
  memcpy(types, mesh_types, sizeof types);
  const MicaVtkCells cells = {MESH_CELLS, mesh_offsets, conn, types};
  snprintf(s->path, sizeof s->path, "%s/bad.vtu", s->dir);
  types[2] = 9; /* a quadrilateral with three nodes */
  assert_int_equal(mica_vtu_write_cells(s->path, 2, MESH_POINTS, mesh_x, &cells, 1, fields), MICA_ERR_ARGUMENT);
  assert_non_null(strstr(mica_error_message(), "cell 2 has VTK type 9 and 3 nodes"));
  types[2] = 77; /* no such type */
  assert_int_equal(mica_vtu_write_cells(s->path, 2, MESH_POINTS, mesh_x, &cells, 1, fields), MICA_ERR_ARGUMENT);
  types[2] = 5, conn[10] = MESH_POINTS; /* a point that does not exist */
  assert_int_equal(mica_vtu_write_cells(s->path, 2, MESH_POINTS, mesh_x, &cells, 1, fields), MICA_ERR_ARGUMENT);
  assert_non_null(strstr(mica_error_message(), "refers to point 7 of 7"));
  conn[10] = 6, value[3] = NAN;
  assert_int_equal(mica_vtu_write_cells(s->path, 2, MESH_POINTS, mesh_x, &cells, 1, fields), MICA_ERR_NUMERIC);
  assert_int_equal(count_entries(s->dir), 0); /* nothing written by any refusal */
  mica_error_clear();
}

static void test_pvd_parts(void **state) {
  Scratch *s = *state;
  const double times[2] = {0.5, 1.0};
  const char *const names[2] = {"particles", "mesh"};
  const char *const files[4] = {"step_0001.vtu", "mesh_0001.vtu", "step_0002.vtu", "mesh_0002.vtu"};
  snprintf(s->path, sizeof s->path, "%s/solution.pvd", s->dir);
  assert_int_equal(mica_pvd_write_parts(s->path, 2, times, 2, names, files), MICA_SUCCESS);
  long size;
  char *text = read_all(s->path, &size);
  const char *first = strstr(text, "<DataSet timestep=\"0.5\" group=\"\" part=\"0\" name=\"particles\" file=\"step_0001.vtu\"/>\n"
                                   "    <DataSet timestep=\"0.5\" group=\"\" part=\"1\" name=\"mesh\" file=\"mesh_0001.vtu\"/>");
  assert_non_null(first);
  assert_non_null(strstr(first, "<DataSet timestep=\"1\" group=\"\" part=\"1\" name=\"mesh\" file=\"mesh_0002.vtu\"/>"));
  free(text);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_vtu_layout, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_vtu_3d_and_empty, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_vtu_refuses_non_finite, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_pvd, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_vtu_cells, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_vtu_refuses_bad_cells, scratch_setup, scratch_teardown),
      cmocka_unit_test_setup_teardown(test_pvd_parts, scratch_setup, scratch_teardown),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
