/* Arguments read against a table of options with glibc's getopt_long, and the help lines of the table.
 * getopt_long runs in its "return words in order" mode ("-" first in the short options): options and
 * words may mix, "--" ends the options, POSIXLY_CORRECT changes nothing, and argv is never reordered.
 * Its own messages are off (":" next): the ones here name the command, suggest the option meant, and
 * end in CLI_USAGE. */
#include <getopt.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "mica/text.h"

enum { MAX_OPTIONS = 32, LONG_CODE = 256, WORD_CODE = 1 /* getopt_long's code for a word */ };

/* What getopt_long returns for option i: its letter, or LONG_CODE + i if it has none. */
static int option_code(const CliOption *options, int i) {
  return options[i].letter ? options[i].letter : LONG_CODE + i;
}

static const CliOption *option_with_code(const CliOption *options, int code) {
  for (int i = 0; options[i].name; i++)
    if (option_code(options, i) == code) return &options[i];
  return NULL;
}

typedef struct {
  struct option longs[MAX_OPTIONS + 1];
  char shorts[2 * MAX_OPTIONS + 3];
} GetoptTables;

static void getopt_tables(const CliOption *options, GetoptTables *tables) {
  int n = 0, k = 0;
  tables->shorts[k++] = '-';
  tables->shorts[k++] = ':';
  for (; options[n].name && n < MAX_OPTIONS; n++) { /* the tables in main.c hold 3 and 2 */
    const int has_value = options[n].value != NULL;
    tables->longs[n] = (struct option){options[n].name, has_value ? required_argument : no_argument, NULL,
                                       option_code(options, n)};
    if (!options[n].letter) continue;
    tables->shorts[k++] = (char)options[n].letter;
    if (has_value) tables->shorts[k++] = ':';
  }
  tables->longs[n] = (struct option){0};
  tables->shorts[k] = '\0';
}

/* ---- messages ---- */

const char *cli_closest(const char *word, const char *const *candidates) {
  const char *best = NULL;
  int best_distance = 1 << 30;
  for (int i = 0; candidates[i]; i++) {
    int distance = mica_text_distance(word, candidates[i]);
    if (distance < best_distance && mica_text_close(distance, word)) {
      best = candidates[i];
      best_distance = distance;
    }
  }
  return best;
}

/* The option's name as written: "--outptu=x" gives "outptu", "-set" gives "set". */
static void written_name(const char *arg, char *buf, size_t size) {
  const char *start = arg + strspn(arg, "-");
  snprintf(buf, size, "%.*s", (int)strcspn(start, "="), start);
}

static int names_of(const CliOption *options, const char **names) {
  int n = 0;
  for (; options[n].name && n < MAX_OPTIONS; n++) names[n] = options[n].name;
  names[n] = NULL;
  return n;
}

/* The options whose names begin with prefix, as "--a, --b"; returns how many. */
static int options_beginning(const CliOption *options, const char *prefix, char *buf, size_t size) {
  int count = 0;
  size_t used = 0;
  buf[0] = '\0';
  for (int i = 0; options[i].name; i++) {
    if (strncmp(options[i].name, prefix, strlen(prefix)) != 0) continue;
    int n = snprintf(buf + used, size - used, "%s--%s", count ? ", " : "", options[i].name);
    if (n > 0 && (size_t)n < size - used) used += (size_t)n;
    count++;
  }
  return count;
}

/* "; did you mean '--output'?" for an unknown option arg (letter: the unknown short one, or 0). */
static void suggestion(const CliOption *options, const char *arg, int letter, char *buf, size_t size) {
  const char *names[MAX_OPTIONS + 1];
  char name[64];
  names_of(options, names);
  written_name(arg, name, sizeof name);
  const char *closest = name[0] && (arg[1] == '-' || strlen(name) > 1) ? cli_closest(name, names) : NULL;
  buf[0] = '\0';
  if (closest) {
    snprintf(buf, size, "; did you mean '--%s'?", closest);
    return;
  }
  for (int i = 0; letter && options[i].name; i++) /* -O for -o */
    if (options[i].letter && (options[i].letter | 0x20) == (letter | 0x20))
      snprintf(buf, size, "; did you mean '-%c'?", options[i].letter);
}

static int unknown_option(const char *who, const CliOption *options, const char *arg, int letter) {
  char name[64], hint[128], matches[256];
  written_name(arg, name, sizeof name);
  if (arg[1] == '-' && options_beginning(options, name, matches, sizeof matches) > 1) {
    fprintf(stderr, "%s: option '--%s' is ambiguous: %s\n", who, name, matches);
    return CLI_USAGE;
  }
  suggestion(options, arg, letter, hint, sizeof hint);
  if (arg[1] == '-') fprintf(stderr, "%s: unknown option '--%s'%s", who, name, hint);
  else if (arg[2]) fprintf(stderr, "%s: unknown option '-%c' (in '%s')%s", who, letter, arg, hint);
  else fprintf(stderr, "%s: unknown option '%s'%s", who, arg, hint);
  if (access(arg, F_OK) == 0) /* a deck whose name starts with '-' */
    fprintf(stderr, " (a file whose name starts with '-' goes after '--': %s -- %s)\n", who, arg);
  else
    fprintf(stderr, " (`%s --help` lists the options)\n", who);
  return CLI_USAGE;
}

/* "--output DIR, --output=DIR or -o DIR" */
static void spellings(const CliOption *option, char *buf, size_t size) {
  if (option->letter)
    snprintf(buf, size, "--%s %s, --%s=%s or -%c %s", option->name, option->value, option->name, option->value,
             option->letter, option->value);
  else
    snprintf(buf, size, "--%s %s or --%s=%s", option->name, option->value, option->name, option->value);
}

static int missing_value(const char *who, const CliOption *option, const char *problem) {
  char forms[256];
  spellings(option, forms, sizeof forms);
  fprintf(stderr, "%s: option '--%s' needs a value%s: %s\n", who, option->name, problem, forms);
  return CLI_USAGE;
}

/* An argument that spells an option of the table: "--set", "--set=x", "-o", "-oDIR". */
static int is_option(const CliOption *options, const char *arg) {
  char name[64];
  written_name(arg, name, sizeof name);
  for (int i = 0; options[i].name; i++) {
    if (arg[0] == '-' && arg[1] == '-' && !strcmp(name, options[i].name)) return 1;
    if (arg[0] == '-' && arg[1] != '-' && arg[1] && arg[1] == options[i].letter) return 1;
  }
  return 0;
}

/* Whether "-" + spelled is a long option written with one dash: its name ("-output"), its name with a
 * value ("-output=DIR") or a prefix of 3 letters or more ("-out"). */
static int spells_long_option(const CliOption *options, const char *spelled) {
  for (int i = 0; options[i].name; i++) {
    size_t n = strlen(options[i].name), length = strcspn(spelled, "=");
    if (length >= 3 && length <= n && !strncmp(spelled, options[i].name, length) && (length == n || !spelled[length]))
      return 1;
  }
  return 0;
}

/* A value getopt_long accepted that is surely a mistake: empty; the next option taken as the value
 * ("-o --set x=1"); or a long name written with one dash ("-output DIR" is -o with the value "utput"). */
static int check_value(const char *who, const CliOption *options, const CliOption *option, const char *element,
                       const char *value, int separate) {
  char spelled[128];
  if (!value[0]) return missing_value(who, option, ", not an empty one");
  if (separate && is_option(options, value)) {
    snprintf(spelled, sizeof spelled, " (it is followed by the option '%s')", value);
    return missing_value(who, option, spelled);
  }
  if (separate || element[1] == '-' || !option->letter) return 0;
  snprintf(spelled, sizeof spelled, "%c%s", option->letter, value);
  if (!spells_long_option(options, spelled)) return 0;
  fprintf(stderr, "%s: '%s' is -%c with the value '%s'; did you mean '-%s'?\n", who, element, option->letter, value,
          element);
  return CLI_USAGE;
}

/* ---- the parser ---- */

/* One return of getopt_long, for the argument argv[at] it was reading. */
static int handle(int code, char **argv, int at, const char *who, const CliOption *options, Invocation *inv) {
  const CliOption *option = option_with_code(options, code == '?' || code == ':' ? optopt : code);
  if (code == ':') return missing_value(who, option, "");
  if (code == '?' && option) { /* a known option without a value, given one */
    fprintf(stderr, "%s: option '--%s' takes no value: '%s'\n", who, option->name, argv[at]);
    return CLI_USAGE;
  }
  if (code == '?') return unknown_option(who, options, argv[at], optopt);
  if (option->value) {
    int status = check_value(who, options, option, argv[at], optarg, optarg == argv[optind - 1]);
    if (status) return status;
  }
  return option->apply(inv, who, optarg);
}

int cli_parse(int argc, char **argv, const char *who, const CliOption *options, Invocation *inv,
              int (*word)(Invocation *inv, const char *who, const char *arg), int *stopped) {
  GetoptTables tables;
  getopt_tables(options, &tables);
  optind = 0; /* glibc: start afresh (a second table, a second parse) */
  opterr = 0;
  int code, status = 0;
  for (int at = 1; !status && !inv->help && !inv->version; at = optind) {
    code = getopt_long(argc, argv, tables.shorts, tables.longs, NULL);
    if (code == -1) break;
    if (code == WORD_CODE) status = word(inv, who, optarg);
    else status = handle(code, argv, at, who, options, inv);
    if (status == CLI_STOP && stopped) *stopped = optind - 1;
  }
  for (int i = optind; !status && !inv->help && !inv->version && i < argc; i++) { /* after "--" */
    status = word(inv, who, argv[i]);
    if (status == CLI_STOP && stopped) *stopped = i;
  }
  return status == CLI_STOP ? 0 : status;
}

/* ---- help ---- */

/* "-o, --output DIR" or "    --set PATH=VALUE" */
static void option_label(const CliOption *option, char *buf, size_t size) {
  char letter[8] = "    ";
  if (option->letter) snprintf(letter, sizeof letter, "-%c, ", option->letter);
  snprintf(buf, size, "%s--%s%s%s", letter, option->name, option->value ? " " : "", option->value ? option->value : "");
}

void cli_print_options(const CliOption *options, FILE *out) {
  char label[128];
  int column = 0;
  for (int i = 0; options[i].name; i++) {
    option_label(&options[i], label, sizeof label);
    int width = mica_text_width(label, sizeof label) + 4;
    if (width > column) column = width;
  }
  for (int i = 0; options[i].name; i++) {
    option_label(&options[i], label, sizeof label);
    fputs("  ", out);
    mica_text_pad(out, label, column - 2);
    mica_text_wrap(out, options[i].help, column, column, CLI_WIDTH, NULL);
  }
}

void cli_print_option_synopsis(const CliOption *options, FILE *out) {
  for (int i = 0; options[i].name; i++) {
    if (!options[i].value) continue;
    if (options[i].letter) fprintf(out, " [-%c %s]", options[i].letter, options[i].value);
    else fprintf(out, " [--%s %s]", options[i].name, options[i].value);
    if (options[i].repeatable) fputs("...", out);
  }
}
