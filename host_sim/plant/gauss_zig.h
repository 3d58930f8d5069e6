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

#include <stdint.h>

#include "plant/rng.h"

#define GAUSS_ZIG_LAYERS 128

typedef struct {
  double x[GAUSS_ZIG_LAYERS + 1]; /* layer widths, decreasing, x[128] = 0 */
  double f[GAUSS_ZIG_LAYERS + 1]; /* f(x[i]) */
} gauss_zig_t;

/* The one layer table every generator shares (gauss_zig_table.c, written by
 * tools/gen_zig_table.py; read-only). */
extern const gauss_zig_t gauss_zig_table;

/* The rare paths of a draw whose fast test failed: layer i, signed uniform v, abscissa
 * x = v x[i]. Returns the deviate (drawing again if it must). */
double gauss_zig_slow(rng_t *r, int i, double v, double x);

/* One N(0,1) deviate from r. Inline: the plant draws about a dozen per sample, and the
 * fast path is a table lookup and a compare. */
static inline double gauss_zig(rng_t *r)
{
  const uint64_t u = rng_next_u64(r);
  const int i = (int)(u & (GAUSS_ZIG_LAYERS - 1));
  /* bits 11..63 (independent of the layer bits): signed uniform in (-1, 1) */
  const double v = ((double)(u >> 11) + 0.5) * 0x1.0p-52 - 1.0;
  const double x = v * gauss_zig_table.x[i];
  const double ax = x < 0.0 ? -x : x;
  if (ax < gauss_zig_table.x[i + 1]) return x;
  return gauss_zig_slow(r, i, v, x);
}

#endif /* PLANT_GAUSS_ZIG_H */
