/* JSON writer and atomic files: layout, escaping, number formats, NaN refused, replacing root keys,
 * API misuse, and that a write leaves either the whole new file or the old one, never a temporary. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mica/files.h"
#include "mica/json.h"

static char *text_of(const MicaJson *json) {
  char *text = NULL;
  if (mica_json_text(json, &text)) fail_msg("%s", mica_error_message());
  return text;
}

static void test_layout(void **state) {
  (void)state;
  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_string(json, "status", "ok"), MICA_SUCCESS);
  assert_int_equal(mica_json_int(json, "particles", 441), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "time", 0.1), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "whole", 3.0), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "sum", 0.1 + 0.2), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "big", -1e300), MICA_SUCCESS);
  assert_int_equal(mica_json_bool(json, "converged", 1), MICA_SUCCESS);
  assert_int_equal(mica_json_open_object(json, "times"), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "assemble", 1.5e-3), MICA_SUCCESS);
  assert_int_equal(mica_json_close(json), MICA_SUCCESS);
  assert_int_equal(mica_json_open_array(json, "errors"), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, NULL, 1.0 / 3.0), MICA_SUCCESS);
  assert_int_equal(mica_json_int(json, NULL, -2), MICA_SUCCESS);
  assert_int_equal(mica_json_close(json), MICA_SUCCESS);
  assert_int_equal(mica_json_open_array(json, "empty"), MICA_SUCCESS);
  assert_int_equal(mica_json_close(json), MICA_SUCCESS);
  char *text = text_of(json);
  assert_string_equal(text, "{\n"
                            "  \"status\": \"ok\",\n"
                            "  \"particles\": 441,\n"
                            "  \"time\": 0.1,\n"
                            "  \"whole\": 3,\n"
                            "  \"sum\": 0.30000000000000004,\n"
                            "  \"big\": -1e+300,\n"
                            "  \"converged\": true,\n"
                            "  \"times\": {\n"
                            "    \"assemble\": 0.0015\n"
                            "  },\n"
                            "  \"errors\": [\n"
                            "    0.3333333333333333,\n" /* shortest text that reads back exactly */
                            "    -2\n"
                            "  ],\n"
                            "  \"empty\": []\n"
                            "}\n");
  free(text);
  mica_json_destroy(&json);
  assert_null(json);
}

static void test_escaping(void **state) {
  (void)state;
  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_string(json, "say \"hi\"", "a\"b\\c\nd\te\001f/\xc3\xa9"), MICA_SUCCESS);
  char *text = text_of(json);
  assert_string_equal(text, "{\n  \"say \\\"hi\\\"\": \"a\\\"b\\\\c\\nd\\te\\u0001f/\xc3\xa9\"\n}\n");
  free(text);
  mica_json_destroy(&json);
}

static void test_non_finite_refused(void **state) {
  (void)state;
  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, "l2_error", NAN), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "'l2_error'"));
  assert_int_equal(mica_json_open_array(json, "history"), MICA_SUCCESS);
  assert_int_equal(mica_json_number(json, NULL, INFINITY), MICA_ERR_NUMERIC);
  assert_non_null(strstr(mica_error_message(), "'history'"));
  assert_int_equal(mica_json_close(json), MICA_SUCCESS);
  mica_error_clear();
  char *text = text_of(json);
  assert_string_equal(text, "{\n  \"history\": []\n}\n");
  free(text);
  mica_json_destroy(&json);
}

/* Setting a root key again replaces its value where it stood. */
static void test_replace_root_key(void **state) {
  (void)state;
  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_string(json, "status", "running"), MICA_SUCCESS);
  assert_int_equal(mica_json_int(json, "dofs", 10), MICA_SUCCESS);
  assert_int_equal(mica_json_string(json, "status", "ok"), MICA_SUCCESS);
  char *text = text_of(json);
  assert_string_equal(text, "{\n  \"status\": \"ok\",\n  \"dofs\": 10\n}\n");
  free(text);
  /* read back: the replaced string; a number or a missing key is refused */
  const char *status = NULL;
  assert_int_equal(mica_json_get_string(json, "status", &status), MICA_SUCCESS);
  assert_string_equal(status, "ok");
  assert_int_equal(mica_json_get_string(json, "dofs", &status), MICA_ERR_ARGUMENT);
  assert_int_equal(mica_json_get_string(json, "reason", &status), MICA_ERR_ARGUMENT);
  mica_error_clear();
  mica_json_destroy(&json);
}

static void test_misuse(void **state) {
  (void)state;
  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_int(json, NULL, 1), MICA_ERR_ARGUMENT); /* object member without key */
  assert_int_equal(mica_json_close(json), MICA_ERR_ARGUMENT);        /* the root stays open */
  assert_int_equal(mica_json_open_array(json, "a"), MICA_SUCCESS);
  assert_int_equal(mica_json_int(json, "k", 1), MICA_ERR_ARGUMENT); /* array element with key */
  char *text = NULL;
  assert_int_equal(mica_json_text(json, &text), MICA_ERR_ARGUMENT); /* "a" still open */
  assert_null(text);
  mica_error_clear();
  mica_json_destroy(&json);
}

static char *read_file(const char *path) {
  static char text[4096];
  FILE *stream = fopen(path, "r");
  if (!stream) return NULL;
  size_t length = fread(text, 1, sizeof text - 1, stream);
  text[length] = '\0';
  fclose(stream);
  return text;
}

static void test_atomic_files(void **state) {
  (void)state;
  char dir[] = "/tmp/mica_test_json_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char *sub = NULL, *path = NULL, *tmp = NULL;
  assert_int_equal(mica_path_join(dir, "a/b/c", &sub), MICA_SUCCESS);
  assert_int_equal(mica_make_dir(sub), MICA_SUCCESS);
  assert_int_equal(mica_make_dir(sub), MICA_SUCCESS); /* exists: fine */
  assert_int_equal(mica_path_join(sub, "summary.json", &path), MICA_SUCCESS);
  assert_int_equal(mica_path_join(sub, ".summary.json.tmp", &tmp), MICA_SUCCESS);

  MicaJson *json = NULL;
  assert_int_equal(mica_json_create(&json), MICA_SUCCESS);
  assert_int_equal(mica_json_string(json, "status", "ok"), MICA_SUCCESS);
  assert_int_equal(mica_json_write(json, path), MICA_SUCCESS);
  mica_json_destroy(&json);
  assert_string_equal(read_file(path), "{\n  \"status\": \"ok\"\n}\n");
  assert_int_equal(access(tmp, F_OK), -1); /* no temporary left behind */

  /* An aborted write leaves the old file as it was and removes its temporary. */
  MicaOutFile out;
  assert_int_equal(mica_out_open(path, &out), MICA_SUCCESS);
  assert_string_equal(out.tmp_path, tmp);
  fputs("half a fi", out.fp);
  assert_int_equal(access(tmp, F_OK), 0);
  mica_out_abort(&out);
  mica_out_abort(&out); /* twice is harmless */
  assert_int_equal(access(tmp, F_OK), -1);
  assert_string_equal(read_file(path), "{\n  \"status\": \"ok\"\n}\n");

  /* A commit replaces it; an abort after the commit changes nothing. */
  assert_int_equal(mica_out_open(path, &out), MICA_SUCCESS);
  fputs("new\n", out.fp);
  assert_int_equal(mica_out_commit(&out), MICA_SUCCESS);
  mica_out_abort(&out);
  assert_string_equal(read_file(path), "new\n");

  /* A directory that cannot exist is an I/O error; the MicaOutFile is safe to abort. */
  char *blocked = NULL;
  assert_int_equal(mica_path_join(path, "x", &blocked), MICA_SUCCESS); /* below a regular file */
  assert_int_equal(mica_make_dir(blocked), MICA_ERR_IO);
  assert_int_equal(mica_out_open(blocked, &out), MICA_ERR_IO);
  mica_out_abort(&out);
  mica_error_clear();

  unlink(path);
  rmdir(sub);
  free(blocked);
  free(tmp);
  free(path);
  free(sub);
  char parent[128];
  snprintf(parent, sizeof parent, "%s/a/b", dir);
  rmdir(parent);
  snprintf(parent, sizeof parent, "%s/a", dir);
  rmdir(parent);
  rmdir(dir);
}

static void test_path_join(void **state) {
  (void)state;
  char *path = NULL;
  assert_int_equal(mica_path_join("out", "summary.json", &path), MICA_SUCCESS);
  assert_string_equal(path, "out/summary.json");
  free(path);
  assert_int_equal(mica_path_join("out/", "x", &path), MICA_SUCCESS);
  assert_string_equal(path, "out/x");
  free(path);
  assert_int_equal(mica_path_join("", "x", &path), MICA_SUCCESS);
  assert_string_equal(path, "x");
  free(path);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_layout),        cmocka_unit_test(test_escaping),
      cmocka_unit_test(test_non_finite_refused), cmocka_unit_test(test_replace_root_key),
      cmocka_unit_test(test_misuse),        cmocka_unit_test(test_atomic_files),
      cmocka_unit_test(test_path_join),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
