/* Neighbor search for MLS: which particles' supports contain a point, k nearest neighbors, and the local
 * particle spacing per axis.
 *
 * Data structures (built by mls_search_create in O(n log n) time and O(n) memory):
 *   - The particles are kept twice: in the caller's order (x, so knn can look up particle i) and in k-d
 *     tree order padded to 3 coordinates (xt, with perm[position] = particle number; the radii rt too,
 *     for the k-d tree kind). Missing axes get coordinate 0 and radius +inf, so every loop runs over 3
 *     axes: 1-D and 2-D need no special cases, and the compiler unrolls the fixed-length loops.
 *   - A k-d tree with leaves of at most LEAF_SIZE particles, split at the median *position* (not value)
 *     along the widest axis, so its depth is about log2(n / LEAF_SIZE) for any cloud, duplicates included.
 *     A left child directly follows its parent and the right child comes after the whole left subtree,
 *     so a reverse sweep over the node array sees children before parents. Each node has two boxes:
 *       * the bounding box of its particles (bounds[node]), which kNN uses to skip nodes farther than
 *         the k-th best;
 *       * the bounding box of its particles' supports x_i ± ρ_i (node[].support, next to the topology
 *         that queries read), refit in O(n) by set_supports, which support queries use: a point outside
 *         it is in none of the node's supports. This stays tight when radii vary per particle, unlike
 *         searching within the largest radius.
 *   - For kind MLS_SEARCH_CELLS, set_supports also builds a uniform grid (O(n + cells)): cell width
 *     = (largest radius along the axis) / CELL_SPLIT, particles binned by position with a counting sort,
 *     ascending particle number within a cell, and each cell's support box. A query visits the at most
 *     (2 CELL_SPLIT + 1)^dim cells within the largest radius of the point and tests the particles of the
 *     cells whose support box contains it. Exact for any radii; efficient when they are of similar size
 *     (the k-d tree adapts better to radii that vary a lot).
 *
 * A support query costs O(log n + c) for c candidates (about twice the s supporting particles on
 * jittered grids) plus an O(s) radix sort (quicksort above RADIX_MAX) to return them in ascending
 * order. It allocates only when the caller's index array must grow and changes no shared state, so
 * queries may run concurrently on one MlsSearch. kNN costs about O(log n + k log k); the local spacing
 * runs it once per particle (k = 2 dim + 2, doubled only where an axis has no candidate yet).
 *
 * Rounding: membership is tested as |x_d − x_id| < ρ_id (box) and sqrt(|x − x_i|²) < ρ_i (ball). If a
 * weight sees r = |Δ|/ρ < 1 in floating point, these tests hold too, so no particle with a nonzero weight
 * is missed. The pruning boxes have rounded ends; a point equal to an end may still be inside a support,
 * so only points strictly outside a box are pruned, which is safe under round-to-nearest.
 */
#include "mica/mls.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
  PAD = MLS_MAX_DIM, /* coordinates stored per particle, whatever dim */
  LEAF_SIZE = 8,     /* particles per leaf: few enough to prune well, enough to amortize a node visit */
  STACK_MAX = 128,   /* traversal stack; exceeds the tree depth + 1 for any n that fits in a long */
  CELL_SPLIT = 2,    /* cells per largest radius along an axis */
  CELLS_PER_PARTICLE = 2, /* at most this many cells per particle (tiny radii would make too many) */
  SORT_SMALL = 16,   /* insertion sort below this many elements */
  RADIX_BITS = 8,    /* radix sort digit */
  RADIX_MAX = 1024   /* radix sort up to this many results, with scratch on the stack */
};

typedef double Vec[PAD];

typedef struct {
  Vec lo, hi;
} Box;

/* What a support query reads, in one 72-byte record; kNN reads the particle boxes (bounds) instead. */
typedef struct {
  Box support;     /* bounding box of the supports of the node's particles */
  long begin, end; /* the node's particles: tree positions [begin, end) */
  long right;      /* the right child (the left one is this node + 1); -1 for a leaf */
} KdNode;

typedef struct {
  Vec origin, width, reach; /* grid corner, cell width, largest radius along each axis */
  long ncell[PAD], total;   /* cells along each axis, and in all */
  long *start;              /* [total + 1]: cell c holds cell-order positions start[c] .. start[c+1]-1 */
  Vec *x, *rho;             /* [n] particles and radii in cell order */
  long *index;              /* [n] particle number at each cell-order position */
  Box *support;             /* [total] support box of each cell */
} CellGrid;

struct MlsSearch {
  int dim;
  long n;
  MlsSearchKind kind;
  double *x;    /* [n*dim] the particles in the caller's order */
  Vec *xt, *rt; /* [n] particles and radii in tree order, padded */
  long *perm;   /* [n] particle number at each tree position */
  KdNode *node;
  Box *bounds; /* [nnode] bounding box of each node's particles */
  long nnode;
  int has_supports;
  MlsSupportKind support;
  CellGrid cells; /* built only for MLS_SEARCH_CELLS */
};

/* ---- small helpers ------------------------------------------------------------------------------- */

/* min and max without fmin/fmax's NaN rules, which keep compilers from inlining them (every value here
 * is finite or infinite, never NaN: coordinates and radii are checked). */
static inline double min_of(double a, double b) { return b < a ? b : a; }
static inline double max_of(double a, double b) { return b > a ? b : a; }

static void pad_point(int dim, const double *x, Vec p) {
  for (int d = 0; d < PAD; d++) p[d] = d < dim ? x[d] : 0.0;
}

static double dist2(const Vec a, const Vec b) {
  double s = 0.0;
  for (int d = 0; d < PAD; d++) s += (a[d] - b[d]) * (a[d] - b[d]);
  return s;
}

/* Whether p lies in the closed box: outside means no support inside the box holds p. */
static inline int box_holds(const Box *b, const Vec p) {
  int in = 1;
  for (int d = 0; d < PAD; d++) in &= (p[d] >= b->lo[d]) & (p[d] <= b->hi[d]);
  return in;
}

static void box_empty(Box *b) {
  for (int d = 0; d < PAD; d++) b->lo[d] = INFINITY, b->hi[d] = -INFINITY;
}

/* Grows b to hold [x − r, x + r]. */
static void box_include(Box *b, const Vec x, const Vec r) {
  for (int d = 0; d < PAD; d++) {
    b->lo[d] = min_of(b->lo[d], x[d] - r[d]);
    b->hi[d] = max_of(b->hi[d], x[d] + r[d]);
  }
}

static void box_union(Box *b, const Box *a, const Box *c) {
  for (int d = 0; d < PAD; d++) {
    b->lo[d] = min_of(a->lo[d], c->lo[d]);
    b->hi[d] = max_of(a->hi[d], c->hi[d]);
  }
}

static inline int is_supported(MlsSupportKind support, const Vec xi, const Vec rho, const Vec p) {
  if (support == MLS_SUPPORT_BALL) return sqrt(dist2(xi, p)) < rho[0];
  int in = 1;
  for (int d = 0; d < PAD; d++) in &= fabs(p[d] - xi[d]) < rho[d];
  return in;
}

static void insertion_sort(long *a, long n) {
  for (long i = 1; i < n; i++) {
    long v = a[i], j = i;
    for (; j > 0 && a[j - 1] > v; j--) a[j] = a[j - 1];
    a[j] = v;
  }
}

static long median3(long a, long b, long c) {
  if (a > b) { long t = a; a = b; b = t; }
  return c < a ? a : c > b ? b : c;
}

/* Ascending quicksort in place on the median of three, recursing into the smaller part so the stack
 * stays O(log n). */
static void quicksort_longs(long *a, long n) {
  while (n > SORT_SMALL) {
    long pivot = median3(a[0], a[n / 2], a[n - 1]), i = 0, j = n - 1;
    while (i <= j) {
      while (a[i] < pivot) i++;
      while (a[j] > pivot) j--;
      if (i <= j) {
        long t = a[i]; a[i] = a[j]; a[j] = t;
        i++, j--;
      }
    }
    if (j + 1 < n - i) {
      quicksort_longs(a, j + 1);
      a += i, n -= i;
    } else {
      quicksort_longs(a + i, n - i);
      n = j + 1;
    }
  }
  insertion_sort(a, n);
}

/* Least-significant-digit radix sort of a[n] (n <= RADIX_MAX) on a − min, ping-ponging with tmp. Its
 * passes are branch free, which matters here: comparison sorts of ~100 scattered particle numbers
 * mispredict about every other branch and took half the time of a query. */
static void radix_sort_longs(long *a, long n, long *tmp) {
  long lo = a[0], hi = a[0];
  for (long i = 1; i < n; i++) lo = a[i] < lo ? a[i] : lo, hi = a[i] > hi ? a[i] : hi;
  const unsigned long range = (unsigned long)(hi - lo);
  long *src = a, *dst = tmp;
  for (int shift = 0; shift < (int)(8 * sizeof range) && (range >> shift) != 0; shift += RADIX_BITS) {
    int start[1 << RADIX_BITS] = {0};
    const unsigned long mask = (1ul << RADIX_BITS) - 1;
    for (long i = 0; i < n; i++) start[((unsigned long)(src[i] - lo) >> shift) & mask]++;
    for (int b = 0, sum = 0; b < (1 << RADIX_BITS); b++) {
      int c = start[b];
      start[b] = sum, sum += c;
    }
    for (long i = 0; i < n; i++) dst[start[((unsigned long)(src[i] - lo) >> shift) & mask]++] = src[i];
    long *t = src; src = dst, dst = t;
  }
  if (src != a) memcpy(a, src, (size_t)n * sizeof *a);
}

/* Ascending sort of query results in place: queries must not allocate, so the radix sort's scratch is
 * on the stack and larger results fall back to quicksort. */
static void sort_results(long *a, long n) {
  if (n <= SORT_SMALL) {
    insertion_sort(a, n);
  } else if (n <= RADIX_MAX) {
    long tmp[RADIX_MAX];
    radix_sort_longs(a, n, tmp);
  } else {
    quicksort_longs(a, n);
  }
}

/* ---- k-d tree construction ----------------------------------------------------------------------- */

static long count_nodes(long m) {
  return m <= LEAF_SIZE ? 1 : 1 + count_nodes(m / 2) + count_nodes(m - m / 2);
}

static void swap_positions(MlsSearch *s, long a, long b) {
  for (int d = 0; d < PAD; d++) {
    double t = s->xt[a][d]; s->xt[a][d] = s->xt[b][d]; s->xt[b][d] = t;
  }
  long t = s->perm[a]; s->perm[a] = s->perm[b]; s->perm[b] = t;
}

static double median3_value(double a, double b, double c) {
  if (a > b) { double t = a; a = b; b = t; }
  return c < a ? a : c > b ? b : c;
}

/* Reorders tree positions [lo, hi] so that position nth holds the value it would have sorted along axis,
 * with no larger value before it and no smaller one after (Hoare's selection). */
static void select_nth(MlsSearch *s, long lo, long hi, long nth, int axis) {
  while (lo < hi) {
    double pivot = median3_value(s->xt[lo][axis], s->xt[(lo + hi) / 2][axis], s->xt[hi][axis]);
    long i = lo, j = hi;
    while (i <= j) {
      while (s->xt[i][axis] < pivot) i++;
      while (s->xt[j][axis] > pivot) j--;
      if (i <= j) swap_positions(s, i++, j--);
    }
    if (nth <= j) hi = j;
    else if (nth >= i) lo = i;
    else return; /* between j and i everything equals the pivot */
  }
}

static void bound_particles(const MlsSearch *s, long begin, long end, Box *b) {
  static const Vec zero = {0.0, 0.0, 0.0};
  box_empty(b);
  for (long p = begin; p < end; p++) box_include(b, s->xt[p], zero);
}

static int widest_axis(const Box *b) {
  int axis = 0;
  for (int d = 1; d < PAD; d++)
    if (b->hi[d] - b->lo[d] > b->hi[axis] - b->lo[axis]) axis = d;
  return axis;
}

/* Builds the subtree of tree positions [begin, end) in preorder; returns its root's node number. */
static long build_subtree(MlsSearch *s, long begin, long end) {
  long id = s->nnode++;
  KdNode *nd = &s->node[id];
  nd->begin = begin, nd->end = end, nd->right = -1;
  bound_particles(s, begin, end, &s->bounds[id]);
  if (end - begin <= LEAF_SIZE) return id;
  long mid = begin + (end - begin) / 2;
  select_nth(s, begin, end - 1, mid, widest_axis(&s->bounds[id]));
  build_subtree(s, begin, mid);
  nd->right = build_subtree(s, mid, end);
  return id;
}

static int build_tree(MlsSearch *s) {
  MICA_CALL(MICA_MALLOC(s->xt, s->n));
  MICA_CALL(MICA_MALLOC(s->perm, s->n));
  MICA_CALL(MICA_MALLOC(s->node, count_nodes(s->n)));
  MICA_CALL(MICA_MALLOC(s->bounds, count_nodes(s->n)));
  for (long i = 0; i < s->n; i++) {
    pad_point(s->dim, s->x + i * s->dim, s->xt[i]);
    s->perm[i] = i;
  }
  s->nnode = 0;
  build_subtree(s, 0, s->n);
  return MICA_SUCCESS;
}

/* Support boxes bottom-up: children follow their parent, so a reverse sweep finishes them first. */
static void refit_supports(MlsSearch *s) {
  for (long id = s->nnode - 1; id >= 0; id--) {
    KdNode *nd = &s->node[id];
    if (nd->right < 0) {
      box_empty(&nd->support);
      for (long p = nd->begin; p < nd->end; p++) box_include(&nd->support, s->xt[p], s->rt[p]);
    } else {
      box_union(&nd->support, &s->node[id + 1].support, &s->node[nd->right].support);
    }
  }
}

/* ---- cell grid ----------------------------------------------------------------------------------- */

static void cells_free(CellGrid *g) {
  MICA_FREE(g->start);
  MICA_FREE(g->x);
  MICA_FREE(g->rho);
  MICA_FREE(g->index);
  MICA_FREE(g->support);
}

/* Cell coordinate of v along axis, clamped to the grid. Monotone in v, so every particle within the
 * largest radius of a point lies in the cell range of [x − reach, x + reach]. */
static long cell_coord(const CellGrid *g, int axis, double v) {
  double t = floor((v - g->origin[axis]) / g->width[axis]);
  if (!(t > 0)) return 0; /* also −inf and NaN */
  if (t >= (double)(g->ncell[axis] - 1)) return g->ncell[axis] - 1;
  return (long)t;
}

static long cell_of(const CellGrid *g, const Vec p) {
  long c = 0;
  for (int d = PAD - 1; d >= 0; d--) c = c * g->ncell[d] + cell_coord(g, d, p[d]);
  return c;
}

/* Cell widths of reach / CELL_SPLIT, widened (all alike) until there are at most
 * CELLS_PER_PARTICLE × n cells: tiny radii must not make the grid outgrow the cloud. */
static void choose_cell_widths(const MlsSearch *s, CellGrid *g) {
  const Box *root = &s->bounds[0];
  double scale = 1.0 / CELL_SPLIT, limit = (double)CELLS_PER_PARTICLE * (double)s->n + 8.0;
  for (;;) {
    double total = 1.0;
    for (int d = 0; d < PAD; d++) {
      double extent = root->hi[d] - root->lo[d];
      g->origin[d] = root->lo[d];
      g->width[d] = d < s->dim ? g->reach[d] * scale : 1.0;
      double count = extent > 0 ? floor(extent / g->width[d]) + 1.0 : 1.0;
      g->ncell[d] = count < limit ? (long)count : (long)limit + 1;
      total *= (double)g->ncell[d];
    }
    if (total <= limit) {
      g->total = g->ncell[0] * g->ncell[1] * g->ncell[2];
      return;
    }
    scale *= 1.25;
  }
}

/* The radii of particle i, padded with +inf (box: one per axis; ball: the one radius on every axis). */
static void particle_radii(const MlsSearch *s, MlsSupportKind support, const double *radii, long i,
                           Vec rho) {
  for (int d = 0; d < PAD; d++)
    rho[d] = d >= s->dim ? INFINITY : radii[i * s->dim + (support == MLS_SUPPORT_BALL ? 0 : d)];
}

static void largest_radii(const MlsSearch *s, MlsSupportKind support, const double *radii, Vec reach) {
  for (int d = 0; d < PAD; d++) reach[d] = 0.0;
  for (long i = 0; i < s->n; i++) {
    Vec rho;
    particle_radii(s, support, radii, i, rho);
    for (int d = 0; d < s->dim; d++) reach[d] = max_of(reach[d], rho[d]);
  }
}

/* Counting sort of the particles into cells, by ascending particle number inside each cell. */
static int cells_fill(const MlsSearch *s, CellGrid *g) {
  long *cell_at = NULL; /* cell of each particle, by particle number */
  MICA_CALL(MICA_MALLOC(cell_at, s->n));
  for (long i = 0; i < s->n; i++) {
    Vec p;
    pad_point(s->dim, s->x + i * s->dim, p);
    cell_at[i] = cell_of(g, p);
  }
  for (long c = 0; c <= g->total; c++) g->start[c] = 0;
  for (long i = 0; i < s->n; i++) g->start[cell_at[i] + 1]++;
  for (long c = 0; c < g->total; c++) g->start[c + 1] += g->start[c];
  for (long i = 0; i < s->n; i++) g->index[g->start[cell_at[i]]++] = i;
  for (long c = g->total; c > 0; c--) g->start[c] = g->start[c - 1]; /* undo the placement shifts */
  g->start[0] = 0;
  free(cell_at);
  return MICA_SUCCESS;
}

/* Coordinates, radii and support box of every cell, in cell order. */
static void cells_copy_particles(const MlsSearch *s, const double *radii, CellGrid *g) {
  for (long c = 0; c < g->total; c++) {
    box_empty(&g->support[c]);
    for (long q = g->start[c]; q < g->start[c + 1]; q++) {
      long i = g->index[q];
      pad_point(s->dim, s->x + i * s->dim, g->x[q]);
      particle_radii(s, s->support, radii, i, g->rho[q]);
      box_include(&g->support[c], g->x[q], g->rho[q]);
    }
  }
}

static int cells_build(MlsSearch *s, const double *radii) {
  CellGrid *g = &s->cells;
  cells_free(g);
  largest_radii(s, s->support, radii, g->reach);
  choose_cell_widths(s, g);
  MICA_CALL(MICA_MALLOC(g->start, g->total + 1));
  MICA_CALL(MICA_MALLOC(g->x, s->n));
  MICA_CALL(MICA_MALLOC(g->rho, s->n));
  MICA_CALL(MICA_MALLOC(g->index, s->n));
  MICA_CALL(MICA_MALLOC(g->support, g->total));
  MICA_CALL(cells_fill(s, g));
  cells_copy_particles(s, radii, g);
  return MICA_SUCCESS;
}

/* ---- support queries ----------------------------------------------------------------------------- */

/* The caller's result array; grows (doubling) only when full. */
typedef struct {
  long *index;
  long count, cap;
} Hits;

static inline int hits_push(Hits *h, long value) {
  if (h->count == h->cap) {
    long grown = h->cap < 16 ? 32 : 2 * h->cap;
    MICA_CALL(MICA_REALLOC(h->index, grown));
    h->cap = grown;
  }
  h->index[h->count++] = value;
  return MICA_SUCCESS;
}

/* Depth first over the nodes whose support box holds p; a child is tested before it is stacked. */
static int tree_query(const MlsSearch *s, const Vec p, Hits *hits) {
  long stack[STACK_MAX];
  int top = 0;
  if (box_holds(&s->node[0].support, p)) stack[top++] = 0;
  while (top > 0) {
    long id = stack[--top];
    const KdNode *nd = &s->node[id];
    if (nd->right >= 0) {
      if (box_holds(&s->node[nd->right].support, p)) stack[top++] = nd->right;
      if (box_holds(&s->node[id + 1].support, p)) stack[top++] = id + 1;
      continue;
    }
    for (long q = nd->begin; q < nd->end; q++)
      if (is_supported(s->support, s->xt[q], s->rt[q], p)) MICA_CALL(hits_push(hits, s->perm[q]));
  }
  return MICA_SUCCESS;
}

static int cells_query(const MlsSearch *s, const Vec p, Hits *hits) {
  const CellGrid *g = &s->cells;
  long lo[PAD], hi[PAD];
  for (int d = 0; d < PAD; d++) {
    lo[d] = cell_coord(g, d, p[d] - g->reach[d]);
    hi[d] = cell_coord(g, d, p[d] + g->reach[d]);
  }
  for (long k2 = lo[2]; k2 <= hi[2]; k2++)
    for (long k1 = lo[1]; k1 <= hi[1]; k1++)
      for (long k0 = lo[0]; k0 <= hi[0]; k0++) {
        long c = (k2 * g->ncell[1] + k1) * g->ncell[0] + k0;
        if (!box_holds(&g->support[c], p)) continue;
        for (long q = g->start[c]; q < g->start[c + 1]; q++)
          if (is_supported(s->support, g->x[q], g->rho[q], p)) MICA_CALL(hits_push(hits, g->index[q]));
      }
  return MICA_SUCCESS;
}

/* ---- k nearest neighbors ------------------------------------------------------------------------- */

/* The k best so far as a max-heap on the squared distance, so the worst is replaced in O(log k). */
typedef struct {
  long *index;
  double *d2;
  int k, count;
  long exclude; /* the particle whose neighbors these are */
} KnnHeap;

static void heap_swap(KnnHeap *h, int a, int b) {
  long ti = h->index[a]; h->index[a] = h->index[b]; h->index[b] = ti;
  double td = h->d2[a]; h->d2[a] = h->d2[b]; h->d2[b] = td;
}

static void heap_sift_down(KnnHeap *h, int top, int size) {
  for (;;) {
    int largest = top, l = 2 * top + 1, r = l + 1;
    if (l < size && h->d2[l] > h->d2[largest]) largest = l;
    if (r < size && h->d2[r] > h->d2[largest]) largest = r;
    if (largest == top) return;
    heap_swap(h, top, largest);
    top = largest;
  }
}

static void heap_offer(KnnHeap *h, long index, double d2) {
  if (h->count < h->k) {
    int c = h->count++;
    h->index[c] = index, h->d2[c] = d2;
    for (; c > 0 && h->d2[(c - 1) / 2] < h->d2[c]; c = (c - 1) / 2) heap_swap(h, c, (c - 1) / 2);
  } else if (d2 < h->d2[0]) {
    h->index[0] = index, h->d2[0] = d2;
    heap_sift_down(h, 0, h->count);
  }
}

/* A node can improve the heap only if it is nearer than its worst entry (ties are not taken). */
static double heap_bound(const KnnHeap *h) { return h->count < h->k ? INFINITY : h->d2[0]; }

/* Heap sort in place: nearest first. */
static void heap_sort_ascending(KnnHeap *h) {
  for (int end = h->count - 1; end > 0; end--) {
    heap_swap(h, 0, end);
    heap_sift_down(h, 0, end);
  }
}

static double box_dist2(const Box *b, const Vec p) {
  double s = 0.0;
  for (int d = 0; d < PAD; d++) {
    double gap = max_of(max_of(b->lo[d] - p[d], p[d] - b->hi[d]), 0.0);
    s += gap * gap;
  }
  return s;
}

/* Depth first, nearer child first, so the bound tightens early. Recursion depth is the tree depth. */
static void knn_visit(const MlsSearch *s, long id, const Vec p, KnnHeap *h) {
  const KdNode *nd = &s->node[id];
  if (nd->right < 0) {
    for (long q = nd->begin; q < nd->end; q++)
      if (s->perm[q] != h->exclude) heap_offer(h, s->perm[q], dist2(s->xt[q], p));
    return;
  }
  long near = id + 1, far = nd->right;
  double dnear = box_dist2(&s->bounds[near], p), dfar = box_dist2(&s->bounds[far], p);
  if (dfar < dnear) {
    long t = near; near = far; far = t;
    double td = dnear; dnear = dfar; dfar = td;
  }
  if (dnear < heap_bound(h)) knn_visit(s, near, p, h);
  if (dfar < heap_bound(h)) knn_visit(s, far, p, h);
}

/* The k nearest particles to p other than exclude, nearest first, into index[k] and d2[k]. */
static void knn_find(const MlsSearch *s, const Vec p, long exclude, int k, long *index, double *d2) {
  KnnHeap h = {index, d2, k, 0, exclude};
  if (k > 0) knn_visit(s, 0, p, &h);
  heap_sort_ascending(&h);
}

/* ---- local spacing ------------------------------------------------------------------------------- */

/* From particle i's neighbors (nearest first), on each side of each axis the nearest whose offset points
 * mainly along that axis (|Δx_d| ≥ |Δx_e| for all e): best[2d + side] its squared distance, side_h its |Δx_d|,
 * side 1 the positive one. Returns the sides found as a bit mask (bit 2d + side). Equally near candidates with
 * different |Δx_d| resolve to the smallest, so the result does not depend on the order of ties. */
static unsigned sides_from_neighbors(const MlsSearch *s, long i, int k, const long *index, const double *d2,
                                     double *best, double *side_h) {
  const int dim = s->dim;
  unsigned found = 0;
  for (int j = 0; j < k; j++) {
    double offset[PAD], largest = 0.0;
    for (int d = 0; d < dim; d++) {
      offset[d] = s->x[index[j] * dim + d] - s->x[i * dim + d];
      largest = max_of(largest, fabs(offset[d]));
    }
    if (largest == 0.0) continue; /* a coincident particle points nowhere */
    for (int d = 0; d < dim; d++) {
      const double delta = fabs(offset[d]);
      if (delta < largest) continue;
      const int side = 2 * d + (offset[d] > 0);
      const unsigned bit = 1u << side;
      if (!(found & bit) || d2[j] < best[side] || (d2[j] == best[side] && delta < side_h[side])) {
        best[side] = d2[j];
        side_h[side] = delta;
        found |= bit;
      }
    }
  }
  return found;
}

/* The far rule takes the farther side up to this many times the nearer side's distance: a particle farther
 * away than that is across a gap (a hole, a notch), not the next one of a graded row, whose spacings grow by
 * far less per step. */
#define SIDE_RATIO 2.0

/* Whether the search must look past the k nearest (the k-th at squared distance dk2): for an axis with no
 * side yet, a farther particle could point mainly along it (|Δx_d|² ≥ dk2 / dim, so the cloud must reach that
 * far along d); under the far rule, for an axis with one side, one on the other side could still be within
 * SIDE_RATIO times the nearer side's distance. This stops the search at once at a boundary and for a layer
 * one particle thick, instead of growing k up to n − 1. The relative margin keeps rounding from stopping it
 * when a bound is met exactly. */
static int farther_could_qualify(const MlsSearch *s, MlsSpacingRule rule, const Vec p, unsigned sides,
                                 const double *side_h, double dk2) {
  const Box *root = &s->bounds[0];
  const double margin = 1.0 + 1e-12;
  for (int d = 0; d < s->dim; d++) {
    const unsigned lower = 1u << (2 * d), upper = lower << 1;
    const double reach_lower = p[d] - root->lo[d], reach_upper = root->hi[d] - p[d];
    if (!(sides & (lower | upper))) {
      const double reach = max_of(reach_lower, reach_upper);
      if (reach * reach * s->dim * margin >= dk2) return 1;
      continue;
    }
    if (rule == MLS_SPACING_NEAR || ((sides & lower) && (sides & upper))) continue;
    const double near = side_h[sides & lower ? 2 * d : 2 * d + 1], reach = sides & lower ? reach_upper : reach_lower;
    const double bound = fmin(reach, SIDE_RATIO * near);
    if (bound * bound * s->dim * margin >= dk2) return 1;
  }
  return 0;
}

/* h along one axis from its sides (mask bits 0 and 1): near, the side of the nearer particle (ties: the
 * smaller |Δx_d|); far, the larger of the two sides' |Δx_d| if it is at most SIDE_RATIO times the smaller,
 * else the smaller. 0 when neither side has one. */
static double axis_spacing(MlsSpacingRule rule, unsigned sides, const double *best, const double *side_h) {
  if (!(sides & 3u)) return 0.0;
  if (sides != 3u) return side_h[sides & 1u ? 0 : 1];
  if (rule == MLS_SPACING_FAR) {
    const double lo = fmin(side_h[0], side_h[1]), hi = fmax(side_h[0], side_h[1]);
    return hi <= SIDE_RATIO * lo ? hi : lo;
  }
  return best[0] < best[1] || (best[0] == best[1] && side_h[0] <= side_h[1]) ? side_h[0] : side_h[1];
}

/* Local spacing of the particle at tree position q by the rule (mica/mls.h, docs/theory.md §supports). Why
 * the far rule exists: in a graded cloud the nearer side is the fine one, so particles reach less far toward
 * the coarse side than their coarse neighbors reach toward them, and just inside a boundary on the coarse side
 * too few particles may cover a point for the basis (the 40:1 graded Cosserat plate at dilation 3 and Gauss
 * order 4 carried a mode along its outer edge that the Gauss points barely see: docs/verification.md §graded
 * supports). index and d2 hold *kmax entries (grown as needed). */
static int spacing_one(const MlsSearch *s, MlsSpacingRule rule, long q, int *kmax, long **index, double **d2,
                       double *h) {
  const long i = s->perm[q];
  const unsigned all = (1u << (2 * s->dim)) - 1;
  const int klast = (int)(s->n - 1 < INT_MAX / 2 ? s->n - 1 : INT_MAX / 2);
  double best[2 * PAD], side_h[2 * PAD];
  unsigned sides = 0;
  for (int k = klast < 2 * s->dim + 2 ? klast : 2 * s->dim + 2;; k = 2 * k < klast ? 2 * k : klast) {
    if (k > *kmax) {
      MICA_CALL(MICA_REALLOC(*index, k));
      MICA_CALL(MICA_REALLOC(*d2, k));
      *kmax = k;
    }
    knn_find(s, s->xt[q], i, k, *index, *d2);
    sides = sides_from_neighbors(s, i, k, *index, *d2, best, side_h);
    if (sides == all || k == klast || !farther_could_qualify(s, rule, s->xt[q], sides, side_h, (*d2)[k - 1]))
      break;
  }
  if (!sides)
    MICA_ERROR(MICA_ERR_INPUT,
               "local spacing: particle %ld has no distinct neighbor (all %ld particles coincide); "
               "give at least two distinct particles",
               i, s->n);
  double largest = 0.0;
  for (int d = 0; d < s->dim; d++) {
    h[d] = axis_spacing(rule, (sides >> (2 * d)) & 3u, best + 2 * d, side_h + 2 * d);
    largest = max_of(largest, h[d]);
  }
  for (int d = 0; d < s->dim; d++)
    if (h[d] == 0.0) h[d] = largest; /* a layer one particle thick: no neighbor along d */
  return MICA_SUCCESS;
}

/* ---- public interface ---------------------------------------------------------------------------- */

int mls_search_create(int dim, long n, const double *x, MlsSearchKind kind, MlsSearch **search) {
  MICA_CHECK(search, MICA_ERR_ARGUMENT, "mls_search_create: search is NULL");
  *search = NULL;
  MICA_CHECK(dim >= 1 && dim <= MLS_MAX_DIM, MICA_ERR_ARGUMENT,
             "mls_search_create: dim = %d, must be 1, 2 or 3", dim);
  MICA_CHECK(n >= 1, MICA_ERR_ARGUMENT, "mls_search_create: n = %ld, need at least one particle", n);
  MICA_CHECK(x, MICA_ERR_ARGUMENT, "mls_search_create: x is NULL");
  MICA_CHECK(kind == MLS_SEARCH_KDTREE || kind == MLS_SEARCH_CELLS, MICA_ERR_ARGUMENT,
             "mls_search_create: unknown search kind %d", (int)kind);
  for (long j = 0; j < n * dim; j++)
    MICA_CHECK(isfinite(x[j]), MICA_ERR_ARGUMENT,
               "mls_search_create: coordinate %d of particle %ld is not finite", (int)(j % dim), j / dim);
  MlsSearch *s = NULL;
  MICA_CALL(MICA_CALLOC(s, 1));
  *search = s;
  s->dim = dim, s->n = n, s->kind = kind;
  int ierr = MICA_SUCCESS;
  MICA_CALL_CLEANUP(MICA_MALLOC(s->x, n * dim));
  memcpy(s->x, x, (size_t)(n * dim) * sizeof *x);
  MICA_CALL_CLEANUP(build_tree(s));
  return MICA_SUCCESS;
cleanup:
  mls_search_destroy(search);
  return ierr;
}

int mls_search_destroy(MlsSearch **search) {
  if (!search || !*search) return MICA_SUCCESS;
  MlsSearch *s = *search;
  cells_free(&s->cells);
  free(s->x);
  free(s->xt);
  free(s->rt);
  free(s->perm);
  free(s->node);
  free(s->bounds);
  free(s);
  *search = NULL;
  return MICA_SUCCESS;
}

static int check_radii(const MlsSearch *s, MlsSupportKind support, const double *radii) {
  int used = support == MLS_SUPPORT_BALL ? 1 : s->dim;
  for (long i = 0; i < s->n; i++)
    for (int d = 0; d < used; d++) {
      double r = radii[i * s->dim + d];
      MICA_CHECK(r > 0 && isfinite(r), MICA_ERR_ARGUMENT,
                 "mls_search_set_supports: radius %d of particle %ld is %g, must be positive and finite",
                 d, i, r);
    }
  return MICA_SUCCESS;
}

int mls_search_set_supports(MlsSearch *search, MlsSupportKind support, const double *radii) {
  MICA_CHECK(search && radii, MICA_ERR_ARGUMENT, "mls_search_set_supports: search or radii is NULL");
  MICA_CHECK(support == MLS_SUPPORT_BOX || support == MLS_SUPPORT_BALL, MICA_ERR_ARGUMENT,
             "mls_search_set_supports: unknown support kind %d", (int)support);
  MICA_CALL(check_radii(search, support, radii));
  MlsSearch *s = search;
  s->has_supports = 0; /* until the structures below are consistent with the new radii */
  s->support = support;
  if (s->kind == MLS_SEARCH_CELLS) {
    MICA_CALL(cells_build(s, radii));
  } else {
    if (!s->rt) MICA_CALL(MICA_MALLOC(s->rt, s->n));
    for (long q = 0; q < s->n; q++) particle_radii(s, support, radii, s->perm[q], s->rt[q]);
    refit_supports(s);
  }
  s->has_supports = 1;
  return MICA_SUCCESS;
}

int mls_search_query(const MlsSearch *search, const double *x, long **index, long *count, long *cap) {
  MICA_CHECK(search && x && index && count && cap, MICA_ERR_ARGUMENT,
             "mls_search_query: NULL argument");
  MICA_CHECK(search->has_supports, MICA_ERR_ARGUMENT,
             "mls_search_query: no supports yet; call mls_search_set_supports first");
  MICA_CHECK(*cap >= 0 && (*cap == 0 || *index), MICA_ERR_ARGUMENT,
             "mls_search_query: capacity %ld needs a non-negative value and, if positive, an index array",
             *cap);
  Vec p;
  pad_point(search->dim, x, p);
  Hits hits = {*index, 0, *cap};
  int ierr = search->kind == MLS_SEARCH_KDTREE ? tree_query(search, p, &hits)
                                                : cells_query(search, p, &hits);
  *index = hits.index, *cap = hits.cap, *count = hits.count;
  MICA_CALL(ierr);
  sort_results(*index, *count);
  return MICA_SUCCESS;
}

int mls_search_knn(const MlsSearch *search, long i, int k, long *index, double *dist2) {
  MICA_CHECK(search, MICA_ERR_ARGUMENT, "mls_search_knn: search is NULL");
  MICA_CHECK(i >= 0 && i < search->n, MICA_ERR_ARGUMENT,
             "mls_search_knn: particle %ld out of range [0, %ld)", i, search->n);
  MICA_CHECK(k >= 0 && k <= search->n - 1, MICA_ERR_ARGUMENT,
             "mls_search_knn: k = %d, must be between 0 and n - 1 = %ld", k, search->n - 1);
  MICA_CHECK(index || k == 0, MICA_ERR_ARGUMENT, "mls_search_knn: index is NULL");
  double *d2 = dist2;
  if (!d2) MICA_CALL(MICA_MALLOC(d2, k));
  Vec p;
  pad_point(search->dim, search->x + i * search->dim, p);
  knn_find(search, p, i, k, index, d2);
  if (d2 != dist2) free(d2);
  return MICA_SUCCESS;
}

int mls_search_local_spacing_rule(const MlsSearch *search, MlsSpacingRule rule, double *h) {
  MICA_CHECK(search && h, MICA_ERR_ARGUMENT, "mls_search_local_spacing: search or h is NULL");
  MICA_CHECK(rule == MLS_SPACING_NEAR || rule == MLS_SPACING_FAR, MICA_ERR_ARGUMENT,
             "mls_search_local_spacing: unknown rule %d", (int)rule);
  const MlsSearch *s = search;
  MICA_CHECK(s->n >= 2, MICA_ERR_INPUT,
             "local spacing: a single particle has no neighbor to measure spacing from; "
             "give at least two particles");
  long *index = NULL;
  double *d2 = NULL;
  int kmax = 0, ierr = MICA_SUCCESS;
  for (long q = 0; q < s->n; q++) /* tree order: consecutive particles are near, so caches stay warm */
    MICA_CALL_CLEANUP(spacing_one(s, rule, q, &kmax, &index, &d2, h + s->perm[q] * s->dim));
cleanup:
  free(index);
  free(d2);
  return ierr;
}

int mls_search_local_spacing(const MlsSearch *search, double *h) {
  return mls_search_local_spacing_rule(search, MLS_SPACING_NEAR, h);
}
