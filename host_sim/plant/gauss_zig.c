#include "plant/gauss_zig.h"

#include <math.h>

static const double kR = 3.442619855899;

/* Tail beyond R: x = R + a with a ~ exp(R) conditioned (Marsaglia 1964). */
static double tail(rng_t *r)
{
  double a, b;
  do {
    a = -log(1.0 - rng_uniform(r)) / kR; /* 1 - u in (0, 1]: log finite */
    b = -log(1.0 - rng_uniform(r));
  } while (b + b < a * a);
  return kR + a;
}

double gauss_zig_slow(rng_t *r, int i, double v, double x)
{
  const gauss_zig_t *z = &gauss_zig_table;
  for (;;) {
    if (i == 0) return v < 0.0 ? -tail(r) : tail(r);
    const double h = z->f[i] + rng_uniform(r) * (z->f[i + 1] - z->f[i]);
    if (h < exp(-0.5 * x * x)) return x;
    /* rejected: a fresh draw, the fast test first */
    const uint64_t u = rng_next_u64(r);
    i = (int)(u & (GAUSS_ZIG_LAYERS - 1));
    v = ((double)(u >> 11) + 0.5) * 0x1.0p-52 - 1.0;
    x = v * z->x[i];
    if (fabs(x) < z->x[i + 1]) return x;
  }
}
