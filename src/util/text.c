/* Text for a terminal: code-point widths, wrapping with a hanging indent, edit distance (libc only). */
#include "mica/text.h"

#include <limits.h>
#include <stdint.h>
#include <string.h>

static int is_continuation(char c) { return ((unsigned char)c & 0xC0) == 0x80; }

static int is_space(char c) { return c == ' ' || c == '\n' || c == '\t'; }

int mica_text_width(const char *text, size_t bytes) {
  int width = 0;
  for (size_t i = 0; i < bytes && text[i]; i++) width += !is_continuation(text[i]);
  return width;
}

void mica_text_pad(FILE *stream, const char *text, int width) {
  fputs(text, stream);
  for (int column = mica_text_width(text, SIZE_MAX); column < width; column++) fputc(' ', stream);
}

/* The next piece of a paragraph: up to the next space, or up to and including a break character. */
static size_t piece_length(const char *text, const char *breaks) {
  size_t n = 0;
  while (text[n] && !is_space(text[n])) {
    n++;
    if (breaks && strchr(breaks, text[n - 1])) break;
  }
  return n;
}

/* Bytes of the longest start of the n bytes of text that fits in `columns`: at least one code point, so
 * that cutting a word always moves on. */
static size_t fitting_bytes(const char *text, size_t n, int columns) {
  size_t bytes = 0;
  for (int used = 0; bytes < n && (used < columns || used == 0); used++) {
    bytes++;
    while (bytes < n && is_continuation(text[bytes])) bytes++;
  }
  return bytes;
}

static void new_line(FILE *stream, int indent) {
  fputc('\n', stream);
  for (int i = 0; i < indent; i++) fputc(' ', stream);
}

void mica_text_wrap(FILE *stream, const char *text, int column, int indent, int width, const char *breaks) {
  int filled = 0, spaced = 0; /* filled: the wrap has put a piece on this line; spaced: a space came before */
  while (*text) {
    if (is_space(*text)) {
      spaced = 1;
      text++;
      continue;
    }
    size_t n = piece_length(text, breaks);
    int w = mica_text_width(text, n), gap = filled && spaced;
    if (column + gap + w > width && (filled || column > indent)) { /* the piece goes to the next line */
      new_line(stream, indent);
      column = indent;
      gap = 0;
    }
    while (n > 0 && column + w > width) { /* wider than a whole line: cut it */
      size_t cut = fitting_bytes(text, n, width - column);
      fwrite(text, 1, cut, stream);
      new_line(stream, indent);
      column = indent;
      text += cut;
      n -= cut;
      w = mica_text_width(text, n);
    }
    if (gap) fputc(' ', stream);
    fwrite(text, 1, n, stream);
    column += gap + w;
    text += n;
    filled = 1;
    spaced = 0;
  }
  fputc('\n', stream);
}

int mica_text_distance(const char *a, const char *b) {
  enum { LONGEST = 80 };
  size_t la = strlen(a), lb = strlen(b);
  if (la >= LONGEST || lb >= LONGEST) return INT_MAX / 2;
  int row[LONGEST];
  for (size_t j = 0; j <= lb; j++) row[j] = (int)j;
  for (size_t i = 1; i <= la; i++) {
    int diagonal = row[0];
    row[0] = (int)i;
    for (size_t j = 1; j <= lb; j++) {
      int above = row[j];
      int best = diagonal + (a[i - 1] != b[j - 1]);
      if (above + 1 < best) best = above + 1;
      if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
      row[j] = best;
      diagonal = above;
    }
  }
  return row[lb];
}

int mica_text_close(int distance, const char *word) {
  int allowed = (int)strlen(word) / 3;
  return distance <= (allowed > 2 ? allowed : 2);
}
