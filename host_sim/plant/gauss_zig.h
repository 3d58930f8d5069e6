/* Standard normal deviates by the ziggurat method (Marsaglia & Tsang 2000, in the
 * ZIGNOR form of Doornik 2005: the layer index and the abscissa come from independent
 * bits of one 64-bit draw, which removes the original's correlation defect). Exact
 * N(0,1) up to the 53-bit resolution of the abscissa; about 1.02 draws of the source's
 * rng_t per deviate and no libm call on the fast path (98.8 % of deviates), against a
 * log and a square root per pair for the polar method of rng_gauss(). For the plant's
 * per-sample noise sources; each source keeps its own rng_t.
 *
 * 128 layers of equal area V = 9.91256303526217e-3 under f(x) = exp(-x^2/2):
 *   x[0] = V / f(R), x[1] = R = 3.442619855899,
 *   x[i+1] = sqrt(-2 ln(V / x[i] + f(x[i]))), x[128] = 0.
 * Draw layer i and u in (-1, 1): x = u x[i]; accept at once if |x| < x[i+1]; in layer 0
 * beyond R, sample the tail (Marsaglia 1964); otherwise accept if a uniform height in
 * [f(x[i]), f(x[i+1])] falls under f(x), else draw again. */
#ifndef PLANT_GAUSS_ZIG_H
#define PLANT_GAUSS_ZIG_H

#include "plant/rng.h"

#define GAUSS_ZIG_LAYERS 128

typedef struct {
  double x[GAUSS_ZIG_LAYERS + 1]; /* layer widths, decreasing, x[128] = 0 */
  double f[GAUSS_ZIG_LAYERS + 1]; /* f(x[i]) */
} gauss_zig_t;

/* Build the layer table (init time). */
void gauss_zig_init(gauss_zig_t *z);

/* One N(0,1) deviate from r. */
double gauss_zig(const gauss_zig_t *z, rng_t *r);

#endif /* PLANT_GAUSS_ZIG_H */
