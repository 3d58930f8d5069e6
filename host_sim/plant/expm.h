/* Dense real matrix exponential for the plant's exact discretisations (host plant,
 * double precision; the one exponential of host_sim/plant).
 *
 * Method: scaling and squaring with the diagonal [13/13] Pade approximant
 * (N. J. Higham, "The scaling and squaring method for the matrix exponential
 * revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005):
 *   s = max(0, ceil(log2(||A||_1 / theta13))),  theta13 = 5.371920351148152
 *   B = A / 2^s
 *   U = B [B6 (b13 B6 + b11 B4 + b9 B2) + b7 B6 + b5 B4 + b3 B2 + b1 I]
 *   V =    B6 (b12 B6 + b10 B4 + b8 B2) + b6 B6 + b4 B4 + b2 B2 + b0 I
 *   r13(B) = (V - U)^-1 (V + U)          (LU with partial pivoting)
 *   exp(A) = r13(B)^(2^s)                 (s squarings)
 * Backward error below the unit roundoff for every ||B||_1 <= theta13.
 *
 * Layout: row-major n x n, element (i, j) at a[i*n + j], n <= EXPM_MAX_N (the
 * plant's largest argument is the pickoff chain driven by a cubic, 4 + 4 states). The
 * workspace (6 matrices of EXPM_MAX_N^2, 3 kB) is on the stack: no hidden state,
 * no allocation, and small enough for the plant on a Cortex-M4 target. The result may
 * not alias the input. Used at init time and on rare re-discretisations (thermal
 * network, DAC reconstruction filter, pickoff chains), never per sample.
 */
#ifndef PLANT_EXPM_H
#define PLANT_EXPM_H

#define EXPM_MAX_N 8

/* e = exp(a). Returns 0 on success, -1 on bad size, a NULL pointer or a non-finite
 * input (e then untouched), -2 if the Pade denominator is numerically singular (cannot
 * happen for finite input within theta13, kept as a guard; e untouched). */
int expm(int n, const double *a, double *e);

#endif /* PLANT_EXPM_H */
