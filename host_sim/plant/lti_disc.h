/* Small dense linear algebra for the exact discretisation of the plant's analog filters
 * (DAC reconstruction filter, pickoff lag and anti-alias chain). Host only, double
 * precision, init-time and on rare re-discretisations, never per sample.
 *
 * Matrix exponential by scaling and squaring with a truncated Taylor series: the
 * argument is scaled by 2^-s until its 1-norm is <= 1/2, the series is summed to degree
 * 18 (truncation < 0.5^19/19! = 1.6e-23 relative to the norm), then squared s times.
 * The plant's arguments have norms of order 1..1e4 and no large negative eigenvalue
 * spread that would make this unstable; a Pade approximant would be cheaper, not more
 * accurate, here.
 *
 * Layout: row-major n x n, element (i, j) at a[i*n + j]; n <= LTI_MAX_N. Results may
 * not alias inputs. No hidden state, no allocation (work arrays on the stack).
 */
#ifndef PLANT_LTI_DISC_H
#define PLANT_LTI_DISC_H

#define LTI_MAX_N 12

/* e = exp(a). Returns 0, or -1 for a bad size or a non-finite entry (e untouched). */
int lti_expm(int n, const double *a, double *e);

/* c = a * b (n x n); c must not alias a or b. */
void lti_matmul(int n, const double *a, const double *b, double *c);

#endif /* PLANT_LTI_DISC_H */
