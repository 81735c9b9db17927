/* libFuzzer harness of the deck loader (`make fuzz`; docs/verification.md "Fuzzing"): mica_deck_load, the
 * entry `mica check` and every other command use, on a deck file written from the input. It reaches the
 * text expansion (deck_text.c: @include, the integer rewriting), libconfig's parser, the --set overrides,
 * the defaults and the schema checks (deck_check.c), then the variants of an overlay list.
 *
 * Input: byte 0 picks the command whose schema checks the deck (mica_command_at, modulo their number); the
 * rest is the deck up to a line "%%", and after it one --set override per line. The deck lives in a private
 * directory beside "part.cfg", a small file it may @include, so includes that resolve are exercised too.
 * Every outcome but a crash, a hang or a leak is fine: a deck either loads or is refused with an error. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mica/command_registry.h"
#include "mica/deck.h"
#include "mica/error.h"

enum { OVERRIDES_MAX = 8, OVERRIDE_LENGTH_MAX = 256 };

static char deck_path[512];

static void write_file(const char *path, const uint8_t *data, size_t size) {
  FILE *f = fopen(path, "wb");
  if (!f) abort();
  if (size && fwrite(data, 1, size, f) != size) abort();
  fclose(f);
}

int LLVMFuzzerInitialize(int *argc, char ***argv) {
  (void)argc, (void)argv;
  char dir[] = "/tmp/mica-fuzz-deck-XXXXXX";
  if (!mkdtemp(dir)) abort();
  snprintf(deck_path, sizeof deck_path, "%s/deck.cfg", dir);
  char part[512];
  snprintf(part, sizeof part, "%s/part.cfg", dir);
  static const char part_text[] = "mls = { order = 2; }\nparameters = { L = 4294967301; }\n";
  write_file(part, (const uint8_t *)part_text, sizeof part_text - 1);
  return 0;
}

/* Splits the overrides after "\n%%\n" into NUL-terminated lines of `store`; returns their number. */
static int split_overrides(const char *text, size_t size, char store[][OVERRIDE_LENGTH_MAX],
                           const char **overrides) {
  int n = 0;
  for (size_t start = 0; start < size && n < OVERRIDES_MAX;) {
    const char *nl = memchr(text + start, '\n', size - start);
    const size_t end = nl ? (size_t)(nl - text) : size;
    const size_t length = end - start < OVERRIDE_LENGTH_MAX - 1 ? end - start : OVERRIDE_LENGTH_MAX - 1;
    if (length > 0 && !memchr(text + start, '\0', length)) {
      memcpy(store[n], text + start, length);
      store[n][length] = '\0';
      overrides[n] = store[n];
      n++;
    }
    start = end + 1;
  }
  return n;
}

static void exercise_variants(const MicaDeck *deck) {
  static const char *const lists[] = {"study.variants", "variants"};
  for (size_t l = 0; l < sizeof lists / sizeof lists[0]; l++) {
    const int n = mica_deck_list_length(deck, lists[l]);
    for (int i = 0; i < n && i < 4; i++) {
      MicaDeck *variant = NULL;
      if (mica_deck_variant(deck, lists[l], i, &variant) == MICA_SUCCESS) (void)mica_deck_name(variant);
      mica_deck_destroy(&variant);
    }
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  int ncommands = 0;
  while (mica_command_at(ncommands)) ncommands++;
  const MicaCommand *command = mica_command_at(data[0] % ncommands);
  const char *text = (const char *)data + 1;
  size_t deck_size = size - 1, rest = 0;
  static const char separator[] = "\n%%\n";
  for (size_t i = 0; i + sizeof separator - 1 <= deck_size; i++)
    if (memcmp(text + i, separator, sizeof separator - 1) == 0) {
      rest = i + sizeof separator - 1;
      deck_size = i + 1;
      break;
    }
  static char store[OVERRIDES_MAX][OVERRIDE_LENGTH_MAX];
  const char *overrides[OVERRIDES_MAX];
  const int noverrides = rest ? split_overrides(text + rest, size - 1 - rest, store, overrides) : 0;
  write_file(deck_path, (const uint8_t *)text, deck_size);
  MicaDeck *deck = NULL;
  if (mica_deck_load(deck_path, command->schema, noverrides, overrides, &deck) == MICA_SUCCESS)
    exercise_variants(deck);
  mica_deck_destroy(&deck);
  mica_error_clear();
  return 0;
}
