#include "plant/gauss_zig.h"

#include <math.h>

static const double kR = 3.442619855899;
static const double kV = 9.91256303526217e-3;

void gauss_zig_init(gauss_zig_t *z)
{
  const double fr = exp(-0.5 * kR * kR);
  z->x[0] = kV / fr;
  z->x[1] = kR;
  z->f[0] = fr;
  z->f[1] = fr;
  for (int i = 1; i < GAUSS_ZIG_LAYERS - 1; i++) {
    z->x[i + 1] = sqrt(-2.0 * log(kV / z->x[i] + z->f[i]));
    z->f[i + 1] = exp(-0.5 * z->x[i + 1] * z->x[i + 1]);
  }
  z->x[GAUSS_ZIG_LAYERS] = 0.0;
  z->f[GAUSS_ZIG_LAYERS] = 1.0;
}

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

double gauss_zig(const gauss_zig_t *z, rng_t *r)
{
  for (;;) {
    const uint64_t u = rng_next_u64(r);
    const int i = (int)(u & (GAUSS_ZIG_LAYERS - 1));
    /* bits 11..63 (independent of the layer bits): signed uniform in (-1, 1) */
    const double v = ((double)(u >> 11) + 0.5) * 0x1.0p-52 - 1.0;
    const double x = v * z->x[i];
    if (fabs(x) < z->x[i + 1]) return x;
    if (i == 0) return v < 0.0 ? -tail(r) : tail(r);
    const double h = z->f[i] + rng_uniform(r) * (z->f[i + 1] - z->f[i]);
    if (h < exp(-0.5 * x * x)) return x;
  }
}
