/* Field models (mica/model.h, "Generalized continua"): the length of the generalized kinematics
 *   q = [ values (ncomp) | gradients (ncomp·dim) | Hessians (ncomp·dim(dim+1)/2), if order 2 ],
 * so nq = ncomp (1 + dim) + (order == 2 ? ncomp dim(dim+1)/2 : 0).
 */
#include "mica/model.h"

/* 0 for arguments outside the contract (no model, dim ∉ {2, 3}, an order other than 1 or 2), so that a
 * caller's check nq > 0 catches them; the function has no error channel of its own. */
int mica_field_model_nq(const MicaFieldModel *m, int dim) {
  if (!m || !m->ops || !m->ops->ncomp || (dim != 2 && dim != 3)) return 0;
  if (m->ops->order != 1 && m->ops->order != 2) return 0;
  int ncomp = m->ops->ncomp(dim);
  if (ncomp <= 0) return 0;
  int nq = ncomp * (1 + dim);
  if (m->ops->order == 2) nq += ncomp * dim * (dim + 1) / 2;
  return nq;
}

int mica_field_model_quadratic(const MicaFieldModel *m) {
  if (mica_type_has(&m->ops->type, MICA_FIELD_CLASSICAL))
    return !mica_type_has(&m->classical->type, MICA_MODEL_FINITE_STRAIN);
  return !mica_type_has(&m->ops->type, MICA_FIELD_FINITE);
}
