/* Eigen double-precision matrix exponential for sizes beyond expm_ref's fixed-capacity
 * 64 (heap storage): the 72 x 72 left-regular representation of the mechanics'
 * truncated algebra, an independent route to host_sim/plant/mech's Taylor blocks.
 * Host tests only. Row-major arrays. */
#ifndef EXPM_LARGE_REF_H
#define EXPM_LARGE_REF_H

#ifdef __cplusplus
extern "C" {
#endif

/* e = exp(a), n x n. Returns 0, or -1 for n outside 1..256. */
int expm_large_ref(int n, const double *a, double *e);

#ifdef __cplusplus
}
#endif

#endif /* EXPM_LARGE_REF_H */
