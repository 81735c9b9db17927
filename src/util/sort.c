/* Orderings for qsort and bsearch (mica/sort.h). */
#include "mica/sort.h"

int mica_compare_long(const void *a, const void *b) {
  const long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}
