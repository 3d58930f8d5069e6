/* Matrix exponential by Eigen's MatrixFunctions module (Pade, scaling and squaring),
 * any size (heap storage): an independent reference for host_sim/plant/expm and for the
 * 72 x 72 left-regular representation behind host_sim/plant/mech's Taylor blocks
 * (test_mech_alg). Host only. */
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
