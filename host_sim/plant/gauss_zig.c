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
  if (i == 0) return v < 0.0 ? -tail(r) : tail(r);
  const double h = z->f[i] + rng_uniform(r) * (z->f[i + 1] - z->f[i]);
  if (h < exp(-0.5 * x * x)) return x;
  return gauss_zig(r); /* rejected: a fresh draw, the fast test first */
}
