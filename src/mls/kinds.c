/* The support shapes, neighbor searches and spacing rules of the MLS library as registries (mica/mls.h):
 * each type is the word the deck uses, a description and the library's enum value. */
#include "mica/mls.h"

static const MlsKindOps support_box = {{"box", "one radius per axis, Φ = Π_d w(r_d) (eq 3.29)", 0, NULL, NULL},
                                       MLS_SUPPORT_BOX};
static const MlsKindOps support_ball = {{"ball", "one radius, Φ = w(|x − x_I|/ρ)", 0, NULL, NULL},
                                        MLS_SUPPORT_BALL};
static const MicaType *const builtin_supports[] = {&support_box.type, &support_ball.type, NULL};
MicaRegistry mls_support_registry = {"support shape", "box", builtin_supports, NULL, 0, NULL};

static const MlsKindOps search_kdtree = {{"kdtree", "a k-d tree over the particles", 0, NULL, NULL},
                                         MLS_SEARCH_KDTREE};
static const MlsKindOps search_cells = {{"cells", "a uniform grid of cells as wide as the largest support", 0,
                                         NULL, NULL},
                                        MLS_SEARCH_CELLS};
static const MicaType *const builtin_searches[] = {&search_kdtree.type, &search_cells.type, NULL};
MicaRegistry mls_search_registry = {"neighbor search", "kdtree", builtin_searches, NULL, 0, NULL};

static const MlsKindOps spacing_near = {{"near", "the nearer neighbor's distance along each axis", 0, NULL, NULL},
                                        MLS_SPACING_NEAR};
static const MlsKindOps spacing_far = {{"far", "the farther side's neighbor distance, if at most twice the nearer "
                                               "(graded clouds)",
                                        0, NULL, NULL},
                                       MLS_SPACING_FAR};
static const MicaType *const builtin_spacings[] = {&spacing_near.type, &spacing_far.type, NULL};
MicaRegistry mls_spacing_registry = {"spacing rule", "near", builtin_spacings, NULL, 0, NULL};
