/* Double-precision references for the demodulators of thesis 5.4 (Eigen, host only).
 *
 * Written from the textbook equations with full 2x2 Eigen matrices, independently of
 * the single-precision firmware kernels (which store three floats of a symmetric P and
 * add guards); the unit tests compare the two.
 *
 * Model (5-1): d(k) = A1 sin(wc k) + A2 cos(wc k) + n(k), phi(k) = [sin, cos]'.
 */
#ifndef DEMOD_REF_H
#define DEMOD_REF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Exponentially weighted RLS, thesis 5.4.2, textbook form
 * K = P phi / (lambda + phi' P phi), W += K err, P = (P - K phi' P) / lambda. */
typedef struct {
  double w[2]; /* [in-phase, quadrature] */
  double p[4]; /* P, row-major */
  double lambda;
} ref_rls_t;

void ref_rls_init(ref_rls_t *s, double lambda, double p0);
void ref_rls_step(ref_rls_t *s, double d, double ref_sin, double ref_cos);

/* Kalman filter (5-11): A = I, Q = q I, R, Joseph-form covariance update. */
typedef struct {
  double x[2]; /* [in-phase, quadrature] */
  double p[4]; /* P, row-major */
  double q, r;
} ref_kf_t;

void ref_kf_init(ref_kf_t *s, double q, double r, double p0);
void ref_kf_step(ref_kf_t *s, double z, double ref_sin, double ref_cos);

/* Batch weighted least squares (5-10) over samples 0..n-1:
 *     W = [Gamma' Lambda Gamma + (lambda^n / p0) I]^-1 Gamma' Lambda d,
 * Lambda = diag(lambda^(n-1), ..., lambda, 1). The prior term is what an RLS started
 * from W = 0, P(0) = p0 I carries (P(n)^-1 = lambda^n P(0)^-1 + Gamma' Lambda Gamma);
 * p0 <= 0 leaves it out (the thesis's pure (5-10)). Solved by a column-pivoting QR of
 * the weighted n x 2 system, not by the recursion. Also returns the information
 * matrix's inverse (row-major, may be NULL). Returns 0, or -1 for bad arguments or a
 * singular system. */
int ref_wls_solve(const double *d, const double *ref_sin, const double *ref_cos, size_t n,
                  double lambda, double p0, double w[2], double p_out[4]);

#ifdef __cplusplus
}
#endif

#endif /* DEMOD_REF_H */
