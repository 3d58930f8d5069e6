/* Converter integral nonlinearity: the bow and the per-code pattern of inl.h. */
#include "plant/inl.h"

#include <math.h>
#include <string.h>

#include "plant/rng.h"

int inl_check(const inl_cfg_t *cfg, int bits)
{
  if (cfg == NULL || bits < 1 || bits > INL_MAX_BITS) return -1;
  const double span = ldexp(1.0, bits);
  if (!(isfinite(cfg->bow_lsb) && fabs(cfg->bow_lsb) <= span)) return -1;
  if (!(isfinite(cfg->code_lsb) && cfg->code_lsb >= 0.0 && cfg->code_lsb <= span)) return -1;
  return 0;
}

/* nib_lsb[k][v]: the weight errors of the set bits of v placed at bits 4k..4k+3 */
static void build_nibbles(inl_t *n)
{
  for (int k = 0; k < INL_MAX_BITS / 4; k++) {
    for (unsigned v = 0; v < 16u; v++) {
      double s = 0.0;
      for (int b = 0; b < 4; b++)
        if ((v >> b) & 1u) s += n->err_lsb[4 * k + b];
      n->nib_lsb[k][v] = s;
    }
  }
}

int inl_init(inl_t *n, const inl_cfg_t *cfg, int bits, uint64_t seed, uint64_t stream)
{
  if (n == NULL || inl_check(cfg, bits) != 0) return -1;
  memset(n, 0, sizeof *n);
  n->bits = bits;
  n->bow_lsb = cfg->bow_lsb;
  n->mid = ldexp(1.0, bits - 1);
  n->active = cfg->bow_lsb != 0.0 || cfg->code_lsb > 0.0;
  n->pattern = cfg->code_lsb > 0.0;
  if (n->pattern) {
    rng_t r;
    rng_seed(&r, seed, stream);
    double sum = 0.0;
    for (int i = 0; i < bits; i++) {
      /* sigma of bit i: code_lsb 2^((i - (bits-1)) / 2) */
      n->err_lsb[i] = cfg->code_lsb * sqrt(ldexp(1.0, i - (bits - 1))) * rng_gauss(&r);
      sum += n->err_lsb[i];
    }
    n->slope_lsb = sum / (ldexp(1.0, bits) - 1.0);
    build_nibbles(n);
  }
  return 0;
}
