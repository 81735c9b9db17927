/* Gauthier & Jahsman's torsion rigidity ratio of a Cosserat cylinder of radius r with a free lateral surface
 * (docs/verification.md §References), an independent reference for the bone-torsion test: no mica code is used.
 *   Ω = 1 + 6 (l_t/r)² (1 − 4Ψχ/3)/(1 − Ψχ),   χ = I₁(pr)/(pr I₀(pr)),   p² = 2ΨN²/((1 − N²) l_t²).
 * Usage: gauthier_jahsman N l_t psi r   → prints Ω.
 * The modified Bessel functions come from their power series, whose terms are all positive, so the sums are
 * accurate to a few ulps for any argument used here (pr ≤ 100). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* I_n(x) = Σ_k (x/2)^(2k+n) / (k! (k+n)!) for n = 0, 1. */
static double bessel_i(int n, double x) {
  double term = n == 0 ? 1.0 : x / 2, sum = term;
  for (int k = 1; k < 500; k++) {
    term *= (x / 2) * (x / 2) / (k * (double)(k + n));
    sum += term;
    if (term < 1e-18 * sum) break;
  }
  return sum;
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s N l_t psi r\n", argv[0]);
    return 2;
  }
  const double N = atof(argv[1]), lt = atof(argv[2]), psi = atof(argv[3]), r = atof(argv[4]);
  const double p = sqrt(2 * psi * N * N / ((1 - N * N) * lt * lt)), x = p * r;
  const double chi = bessel_i(1, x) / (x * bessel_i(0, x));
  const double omega = 1 + 6 * (lt / r) * (lt / r) * (1 - 4 * psi * chi / 3) / (1 - psi * chi);
  printf("%.10g\n", omega);
  return 0;
}
