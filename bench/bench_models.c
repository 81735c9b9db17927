/* Cost of each continuum model per quadrature point, relative to linear elasticity: the field model's
 * eval (W, s and the tangent D) at random kinematics, in 2-D and 3-D, best of 3. The assembly cost per
 * point grows further with the number of unknowns and q's length (B entries per particle); nq is printed.
 * Prints figures only; never fails on time. */
#include <stdio.h>
#include <string.h>

#include "mica/cosserat.h"
#include "mica/micromorph.h"
#include "mica/model.h"
#include "mica/random.h"
#include "mica/timer.h"

typedef struct {
  const char *name;
  MicaFieldModel model;
} Case;

static double time_eval(const MicaFieldModel *m, int dim, long reps) {
  const int nq = mica_field_model_nq(m, dim);
  double q[128], s[128], D[128 * 128], W, best = 1e300;
  MicaRandom rng = mica_random_seed(5);
  for (int j = 0; j < nq; j++) q[j] = 0.05 * (2 * mica_random_uniform(&rng) - 1);
  for (int rep = 0; rep < 3; rep++) {
    const double t0 = mica_wtime();
    for (long i = 0; i < reps; i++) {
      q[i % nq] += 1e-12; /* keep the compiler from hoisting the call */
      if (m->ops->eval(m, dim, q, &W, s, D)) return -1;
    }
    const double t = (mica_wtime() - t0) / (double)reps;
    if (t < best) best = t;
  }
  return best;
}

static int add_cases(int dim, Case *cases) {
  int n = 0;
  MicaMaterial mat;
  const MicaPlaneKind plane = dim == 2 ? MICA_PLANE_STRAIN : MICA_PLANE_NONE;
  const MicaModelOps *classical[] = {&mica_model_linear, &mica_model_svk, &mica_model_neohooke, &mica_model_neohooke_cook};
  for (int k = 0; k < 4; k++) {
    mica_material_set(classical[k], 1000, 0.3, plane, &mat);
    cases[n].name = classical[k]->type.name;
    mica_field_classical_set(&cases[n++].model, classical[k], &mat);
  }
  cases[n].name = "cosserat";
  mica_cosserat_set_technical(&cases[n++].model, dim, 1000, 0.3, 0.5, 0.1, 0.1, 1.0);
  cases[n].name = "cosserat-finite";
  mica_cosserat_set_technical(&cases[n].model, dim, 1000, 0.3, 0.5, 0.1, 0.1, 1.0);
  mica_cosserat_finite_set(&cases[n++].model);
  mica_material_set(&mica_model_linear, 1000, 0.3, plane, &mat);
  const double line[3] = {0, 0.5, 0}, box[3] = {0.5, 0.5, dim == 3 ? 0.5 : 0};
  cases[n].name = "micromorph (linear, micro line)";
  mica_micromorph_set(&cases[n++].model, dim, &mica_model_linear, &mat, line);
  cases[n].name = "micromorph (linear, micro box)";
  mica_micromorph_set(&cases[n++].model, dim, &mica_model_linear, &mat, box);
  mica_material_set(&mica_model_svk, 1000, 0.3, plane, &mat);
  cases[n].name = "micromorph (svk, micro box)";
  mica_micromorph_set(&cases[n++].model, dim, &mica_model_svk, &mat, box);
  cases[n].name = "mm isochoric (svk, line)";
  mica_micromorph_isochoric_set(&cases[n++].model, dim, &mica_model_svk, &mat, line);
  cases[n].name = "mm isochoric (svk, box)";
  mica_micromorph_isochoric_set(&cases[n++].model, dim, &mica_model_svk, &mat, box);
  cases[n].name = "mm rotation (svk, line)";
  mica_micromorph_rotation_set(&cases[n++].model, dim, &mica_model_svk, &mat, line, 0.5);
  cases[n].name = "mm rotation (svk, box)";
  mica_micromorph_rotation_set(&cases[n++].model, dim, &mica_model_svk, &mat, box, 0.5);
  mica_material_set(&mica_model_linear, 1000, 0.3, plane, &mat);
  cases[n].name = "strain-gradient";
  mica_strain_gradient_set(&cases[n++].model, &mat, 0.1, 0);
  cases[n].name = "couple-stress";
  mica_strain_gradient_set(&cases[n++].model, &mat, 0.1, 1);
  return n;
}

int main(void) {
  printf("model kernels: W, s and D per quadrature point, best of 3 (ratio to linear elasticity)\n");
  for (int dim = 2; dim <= 3; dim++) {
    Case cases[16];
    const int n = add_cases(dim, cases);
    const double base = time_eval(&cases[0].model, dim, 200000);
    for (int i = 0; i < n; i++) {
      const long reps = i < 6 ? 200000 : 5000;
      const double t = time_eval(&cases[i].model, dim, reps);
      printf("%d-D  %-34s  nq %3d  %9.0f ns  ratio %7.1f\n", dim, cases[i].name,
             mica_field_model_nq(&cases[i].model, dim), t * 1e9, t / base);
    }
  }
  return 0;
}
