/* Matrix exponential by Eigen's MatrixFunctions module (Pade, scaling and squaring),
 * an independent reference for host_sim/plant/lti_disc. Host only. */
#ifndef MATEXP_REF_H
#define MATEXP_REF_H

#ifdef __cplusplus
extern "C" {
#endif

/* e = exp(a), row-major n x n. Returns 0, or -1 for n < 1. */
int ref_matexp(int n, const double *a, double *e);

#ifdef __cplusplus
}
#endif

#endif /* MATEXP_REF_H */
