/* Least-squares fit of sinusoids of known frequencies plus a constant to sampled data
 * (Eigen, Householder QR, double precision): amplitude/phase reference for the plant's
 * analog-chain tests. Host only. */
#ifndef SINE_FIT_REF_H
#define SINE_FIT_REF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Model y[k] = c0 + sum_i (a_i cos(w_i t_k) + b_i sin(w_i t_k)), t_k = t0 + k * dt,
 * w_i = 2 pi f_hz[i]. coef receives [c0, a_0, b_0, a_1, b_1, ...] (1 + 2 nf values).
 * Returns the rms residual, or -1 on bad arguments (n < 1 + 2 nf, nf < 1). */
double ref_sine_fit(const double *y, size_t n, double t0_s, double dt_s, const double *f_hz,
                    size_t nf, double *coef);

#ifdef __cplusplus
}
#endif

#endif /* SINE_FIT_REF_H */
