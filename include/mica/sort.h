/* Orderings for qsort and bsearch shared by the stages that sort particle, node and key lists. */
#ifndef MICA_SORT_H
#define MICA_SORT_H

/* Ascending order of two longs (the first long of each element: records of several longs sort by it). */
int mica_compare_long(const void *a, const void *b);

#endif
