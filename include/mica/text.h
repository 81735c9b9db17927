/* Text for a terminal (the help of `mica`): widths counted in code points of UTF-8, so that "±" or "§" is
 * one column; paragraphs wrapped with a hanging indent; the edit distance behind "did you mean". */
#ifndef MICA_TEXT_H
#define MICA_TEXT_H

#include <stddef.h>
#include <stdio.h>

/* Columns taken by the first `bytes` bytes of text (its code points; SIZE_MAX: up to the NUL). */
int mica_text_width(const char *text, size_t bytes);

/* Prints text, then spaces up to `width` columns (none if the text is as wide or wider). */
void mica_text_pad(FILE *stream, const char *text, int width);

/* Prints text as one paragraph (newlines count as spaces) from column `column`, where the caller's line
 * already ends, breaking it at spaces and after any character of `breaks` (NULL: none) so that no line
 * is wider than `width`; each further line starts with `indent` spaces. A word wider than a whole line is
 * cut. Ends with a newline; leaves no trailing spaces. */
void mica_text_wrap(FILE *stream, const char *text, int column, int indent, int width, const char *breaks);

/* Levenshtein distance between two words; words of 80 bytes or more count as far apart. */
int mica_text_distance(const char *a, const char *b);
/* Whether a word at that distance from a known one is close enough to suggest it. */
int mica_text_close(int distance, const char *word);

#endif
