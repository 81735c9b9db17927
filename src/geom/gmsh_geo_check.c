/* What a .geo may do before the Gmsh library runs it (docs/input.md, geometry.mesh). A .geo is a Gmsh program,
 * and Gmsh 4.8 has no option that forbids its commands that run programs (its `gmsh -help_options` and C API
 * have none), so mica reads the script as Gmsh's lexer does (// and block comments, "..." and '...' strings,
 * words) and refuses, with file:LINE:
 *   - commands that run programs: SystemCall, System, NonBlockingSystemCall (a shell command), OnelabRun
 *     (a ONELAB client program);
 *   - Exit, which ends the whole process (mica's too) at once;
 *   - commands that write files: Save, Print, CreateDir, Printf(...) > "file", Plugin (plugins may save views);
 *   - Include and Merge of a file not named by a plain string (mica could not check it); an Included file,
 *     and a Merged .geo or .pos script, is checked the same way; Merge takes geometry and mesh files (.step,
 *     .stp, .iges, .igs, .brep, .brp, .stl, .msh) without reading them, and anything else (a .py or .pro
 *     that ONELAB would run as a solver, an unknown extension that Gmsh would parse as a script) is refused;
 *   - a NUL byte (Gmsh's lexer would stop reading there) and a string longer than Gmsh reads (1023 bytes: the
 *     rest would be read as commands).
 * Word commands (SystemCall, Save, ...) are Gmsh identifiers, so a variable may have their name: they count as
 * commands when a string expression follows (a string, a word or '('), as in Gmsh's grammar. Exit, Plugin,
 * OnelabRun and Printf are keywords of Gmsh's lexer and count wherever they appear.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "gmsh_reader.h"

enum { DEPTH_MAX = 16, STRING_MAX = 1023, WORD_MAX = 64, FILE_NAME_MAX = 1024 };

typedef enum { TOK_END, TOK_WORD, TOK_STRING, TOK_PUNCT } TokenKind;

typedef struct {
  TokenKind kind;
  long line;
  const char *text; /* into the buffer: the word, the string's content, or the punctuation */
  size_t len;
} Token;

typedef struct {
  const char *path;
  const char *buf;
  size_t len, pos;
  long line;
} Script;

/* "file:LINE: <what><name><why>" */
static int fail(const Script *s, long line, const char *what, const char *name, const char *why) {
  return mica_error_set(__FILE__, __LINE__, __func__, MICA_ERR_INPUT, "%s:%ld: %s%s%s", s->path, line, what,
                        name, why);
}

/* ---- tokens ---- */

static int is_alpha(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_digit(int c) { return c >= '0' && c <= '9'; }

/* Skips blanks and comments; an unterminated block comment runs to the end, as in Gmsh. */
static void skip_blank(Script *s) {
  while (s->pos < s->len) {
    const char c = s->buf[s->pos], d = s->pos + 1 < s->len ? s->buf[s->pos + 1] : '\0';
    if (c == '\n') {
      s->line++, s->pos++;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f') {
      s->pos++;
    } else if (c == '/' && d == '/') {
      while (s->pos < s->len && s->buf[s->pos] != '\n') s->pos++;
    } else if (c == '/' && d == '*') {
      s->pos += 2;
      while (s->pos < s->len && !(s->buf[s->pos] == '*' && s->pos + 1 < s->len && s->buf[s->pos + 1] == '/'))
        s->line += s->buf[s->pos++] == '\n';
      s->pos = s->pos < s->len ? s->pos + 2 : s->len;
    } else {
      return;
    }
  }
}

static int next_token(Script *s, Token *t) {
  skip_blank(s);
  t->line = s->line;
  if (s->pos >= s->len) {
    t->kind = TOK_END, t->text = "", t->len = 0;
    return MICA_SUCCESS;
  }
  const char c = s->buf[s->pos];
  const size_t start = s->pos;
  if (c == '"' || c == '\'') {
    s->pos++;
    while (s->pos < s->len && s->buf[s->pos] != c) s->line += s->buf[s->pos++] == '\n';
    t->kind = TOK_STRING, t->text = s->buf + start + 1, t->len = s->pos - start - 1;
    if (s->pos < s->len) s->pos++;
    if (t->len > STRING_MAX)
      return fail(s, t->line, "a string longer than ", "1023 bytes",
                  ", which Gmsh would cut and read the rest of as commands: mica refuses it");
    return MICA_SUCCESS;
  }
  if (is_alpha(c)) {
    while (s->pos < s->len && (is_alpha(s->buf[s->pos]) || is_digit(s->buf[s->pos]))) s->pos++;
    t->kind = TOK_WORD;
  } else {
    s->pos++;
    if (c == '>' && s->pos < s->len && s->buf[s->pos] == '>') s->pos++; /* ">>" appends, like ">" writes */
    t->kind = TOK_PUNCT;
  }
  t->text = s->buf + start, t->len = s->pos - start;
  return MICA_SUCCESS;
}

static int is(const Token *t, const char *text) { return t->len == strlen(text) && !memcmp(t->text, text, t->len); }

static int is_one_of(const Token *t, const char *const *words) {
  for (; *words; words++)
    if (is(t, *words)) return 1;
  return 0;
}

/* ---- files named by Include and Merge ---- */

static const char *extension(const char *name) {
  const char *dot = strrchr(name, '.'), *slash = strrchr(name, '/');
  return dot && (!slash || dot > slash) ? dot + 1 : "";
}

static int check_file(const char *path, int depth);

/* word (Include, Merge) names `name` at `line` of s. */
static int check_named(const Script *s, const char *word, const Token *name, long line, int depth) {
  static const char *const data[] = {"step", "stp", "iges", "igs", "brep", "brp", "stl", "msh", NULL};
  static const char *const scripts[] = {"geo", "geo_unrolled", "pos", NULL};
  char file[FILE_NAME_MAX], quoted[FILE_NAME_MAX + 4];
  if (name->len >= FILE_NAME_MAX - 1) return fail(s, line, word, " names a file with a too long name", "");
  const char *slash = strrchr(s->path, '/');
  const int dir = name->text[0] == '/' || !slash ? 0 : (int)(slash - s->path + 1); /* Gmsh: relative to this file */
  snprintf(file, sizeof file, "%.*s%.*s", dir, s->path, (int)name->len, name->text);
  snprintf(quoted, sizeof quoted, " '%.*s'", (int)name->len, name->text);
  const char *ext = extension(file);
  int script = strcmp(word, "Include") == 0;
  for (int i = 0; !script && data[i]; i++)
    if (!strcasecmp(ext, data[i])) return MICA_SUCCESS;
  for (int i = 0; !script && scripts[i]; i++) script = !strcasecmp(ext, scripts[i]);
  if (!script)
    return fail(s, line, word, quoted,
                ": a .geo may merge geometry and mesh files (.step .stp .iges .igs .brep .brp .stl .msh) and Gmsh "
                "scripts (.geo .pos, checked like this one); Gmsh would run or parse anything else as a program");
  if (depth >= DEPTH_MAX)
    return fail(s, line, word, quoted, ": the includes nest deeper than 16 files (does a file include itself?)");
  FILE *f = fopen(file, "rb");
  if (!f) {
    char why[FILE_NAME_MAX + 128];
    snprintf(why, sizeof why, ": mica cannot open %s to check it: %s", file, strerror(errno));
    return fail(s, line, word, quoted, why);
  }
  fclose(f);
  return check_file(file, depth + 1);
}

/* ---- the script ---- */

static const char *const RUNS[] = {"SystemCall", "System", "NonBlockingSystemCall", NULL};
static const char *const WRITES[] = {"Save", "Print", "CreateDir", NULL};
static const char *const READS[] = {"Include", "Merge", "MergeWithBoundingBox", NULL};

/* A string expression follows: a string, a word (a string variable or a function such as StrCat), '('. */
static int starts_string(const Token *t) { return t->kind == TOK_STRING || t->kind == TOK_WORD || is(t, "("); }

static int check_keyword(const Script *s, const Token *t) {
  char word[WORD_MAX];
  snprintf(word, sizeof word, "%.*s", (int)t->len, t->text);
  if (is(t, "Exit"))
    return fail(s, t->line, word, "", " would end mica at once, with nothing written: remove it");
  if (is(t, "OnelabRun"))
    return fail(s, t->line, word, "", " runs a program: mica runs no program a .geo names; remove it");
  if (is(t, "Plugin"))
    return fail(s, t->line, word, "", " runs a Gmsh plugin, which may write files: mica meshes with geometry "
                                      "and mesh commands only; remove it");
  return MICA_SUCCESS;
}

/* A word command followed by next (a string expression when it is a command). */
static int check_command(const Script *s, const Token *t, const Token *next, Script *ahead, int depth) {
  char word[WORD_MAX];
  snprintf(word, sizeof word, "%.*s", (int)t->len, t->text);
  if (!starts_string(next)) return MICA_SUCCESS;
  if (is_one_of(t, RUNS))
    return fail(s, t->line, word, "", " runs a shell command: mica lets nothing a user shares as input reach a "
                                      "shell; remove it");
  if (is_one_of(t, WRITES))
    return fail(s, t->line, word, "", " writes files: mica meshes the .geo without writing any; remove it");
  if (!is_one_of(t, READS)) return MICA_SUCCESS;
  Token end;
  MICA_CALL(next_token(ahead, &end));
  if (next->kind != TOK_STRING || !is(&end, ";"))
    return fail(s, t->line, word, "", " must name its file as a plain string (\"part.step\") so that mica can "
                                      "check what the .geo reads");
  return check_named(s, word, next, t->line, depth);
}

/* Printf(...) > "file" and >> "file" write files; Printf(...) to the terminal is silent (General.Terminal = 0). */
static int check_printf(const Script *s, const Token *t, Script *ahead) {
  Token u;
  int depth = 0, opened = 0;
  do {
    MICA_CALL(next_token(ahead, &u));
    if (is(&u, "(")) depth++, opened = 1;
    if (is(&u, ")")) depth--;
  } while (u.kind != TOK_END && !is(&u, ";") && !(opened && depth == 0));
  if (opened && depth == 0) MICA_CALL(next_token(ahead, &u));
  if (is(&u, ">") || is(&u, ">>"))
    return fail(s, t->line, "Printf", "", " into a file writes files: mica meshes the .geo without writing any; "
                                          "remove the redirection");
  return MICA_SUCCESS;
}

static int check_script(Script *s, int depth) {
  static const char *const keywords[] = {"Exit", "OnelabRun", "Plugin", NULL};
  Token t, next;
  MICA_CALL(next_token(s, &t));
  while (t.kind != TOK_END) {
    const Script at_next = *s; /* to look further ahead without losing the place */
    MICA_CALL(next_token(s, &next));
    if (t.kind == TOK_WORD) {
      Script ahead = at_next;
      if (is_one_of(&t, keywords)) MICA_CALL(check_keyword(s, &t));
      if (is(&t, "Printf")) MICA_CALL(check_printf(s, &t, &ahead));
      ahead = *s;
      MICA_CALL(check_command(s, &t, &next, &ahead, depth));
    }
    t = next;
  }
  return MICA_SUCCESS;
}

static int check_file(const char *path, int depth) {
  int ierr = MICA_SUCCESS;
  char *buf = NULL;
  size_t len = 0;
  MICA_CALL(gmsh_load_file(path, ".geo file", &buf, &len));
  Script s = {path, buf, len, 0, 1};
  const char *nul = memchr(buf, '\0', len);
  if (nul) {
    long line = 1;
    for (const char *p = buf; p < nul; p++) line += *p == '\n';
    ierr = fail(&s, line, "a NUL byte", "", ": a .geo is a text file (Gmsh would stop reading there)");
    goto cleanup;
  }
  MICA_CALL_CLEANUP(check_script(&s, depth));
cleanup:
  MICA_FREE(buf);
  return ierr;
}

int gmsh_geo_check(const char *path) { return check_file(path, 0); }
