/* Kaloni & Ariman's stress concentration factor at a circular hole in an infinite Cosserat plate under
 * uniaxial tension (docs/verification.md §References):
 * c = l/N, F = 8 (1 − ν) N² / (4 + (a/c)² + 2 (a/c) K0(a/c)/K1(a/c)),
 * SCF = (3 + F)/(1 + F). The modified Bessel functions come from K_n(x) = ∫_0^∞ exp(−x cosh t) cosh(n t) dt
 * by composite Simpson on [0, T] with exp(−x cosh T) < 1e-300.
 * Usage: kaloni_ariman NU N A_OVER_L   (prints the SCF) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static double bessel_k(int n, double x) {
  const double T = acosh(fmax(700.0 / x, 1.0)) + 1.0;
  const int steps = 200000; /* even */
  const double h = T / steps;
  double sum = 0;
  for (int i = 0; i <= steps; i++) {
    const double t = i * h, f = exp(-x * cosh(t)) * cosh(n * t);
    sum += f * (i == 0 || i == steps ? 1 : (i % 2 ? 4 : 2));
  }
  return sum * h / 3;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s NU N A_OVER_L\n", argv[0]);
    return 2;
  }
  const double nu = atof(argv[1]), N = atof(argv[2]), a_over_l = atof(argv[3]);
  const double a_over_c = a_over_l * N; /* c = l / N */
  const double F = 8 * (1 - nu) * N * N /
                   (4 + a_over_c * a_over_c + 2 * a_over_c * bessel_k(0, a_over_c) / bessel_k(1, a_over_c));
  printf("%.10f\n", (3 + F) / (1 + F));
  return 0;
}
