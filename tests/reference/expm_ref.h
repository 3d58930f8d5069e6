/* Eigen double-precision reference for the plant's exact discretisations: matrix
 * exponential from Eigen's unsupported MatrixFunctions module (host tests only; Eigen
 * never reaches host_sim or the firmware). Row-major arrays throughout. */
#ifndef EXPM_REF_H
#define EXPM_REF_H

#ifdef __cplusplus
extern "C" {
#endif

/* e = exp(a), n x n. Returns 0, or -1 for n outside 1..64. */
int expm_ref(int n, const double *a, double *e);

/* One exact zero-order-hold step of x' = A x + B u over dt:
 *   x <- exp(A dt) x + (int_0^dt exp(A s) ds) B u
 * through the augmented exponential exp([A B; 0 0] dt). n <= 32 states, m <= 8
 * inputs. Returns 0, or -1 on bad sizes. */
int expm_ref_zoh_step(int n, int m, const double *a, const double *b, const double *u,
                      double dt, double *x);

#ifdef __cplusplus
}
#endif

#endif /* EXPM_REF_H */
