/* Double-precision IIR references for the filter tests (host only).
 *
 * Sections are rows of 6 doubles {b0, b1, b2, a0, a1, a2} as scipy.signal's sos, with
 * H(z) = prod (b0 + b1 z^-1 + b2 z^-2) / (a0 + a1 z^-1 + a2 z^-2).
 * The filter runs in long double, direct form I (not the TDF-II of dsp/biquad.h), so a
 * float kernel is judged against an independent structure and precision. */
#ifndef IIR_REF_H
#define IIR_REF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* y[i] = cascade(x)[i], zero initial state. x and y may alias. */
void iir_ref_sos_filter(const double *sos, size_t n_sections, const double *x, double *y,
                        size_t n);

/* H(exp(j 2 pi f/fs)) of the cascade. */
void iir_ref_sos_freqresp(const double *sos, size_t n_sections, double f_hz, double fs_hz,
                          double *re, double *im);

/* Roots of c[0] z^order + c[1] z^(order-1) + ... + c[order] (c[0] != 0), from the
 * eigenvalues of the companion matrix (Eigen). Returns the number of roots (order), or
 * -1 if c[0] == 0 or order is 0. */
int iir_ref_poly_roots(const double *c, size_t order, double *re, double *im);

#ifdef __cplusplus
}
#endif

#endif /* IIR_REF_H */
