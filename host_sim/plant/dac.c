#include "plant/dac.h"

#include <math.h>
#include <string.h>

#include "plant/expm.h"
#include "plant/plant_const.h"
#include "board.h"

static const double k_pi = PLANT_PI;

double dac_code_to_v(uint16_t code)
{
  return ((double)code - (double)HAL_DAC_CODE_MID) *
         (2.0 * (double)HAL_DAC_FULL_SCALE_V / 16384.0);
}

uint16_t dac_v_to_code(double v)
{
  const double lsb = 2.0 * (double)HAL_DAC_FULL_SCALE_V / 16384.0;
  if (isnan(v)) return (uint16_t)HAL_DAC_CODE_MID;
  double c = floor(v / lsb + 0.5) + (double)HAL_DAC_CODE_MID;
  if (c < 0.0) c = 0.0;
  if (c > (double)HAL_DAC_CODE_MAX) c = (double)HAL_DAC_CODE_MAX;
  return (uint16_t)c;
}

void dac_default_cfg(dac_cfg_t *cfg)
{
  memset(cfg, 0, sizeof *cfg);
  cfg->fs_hz = (double)BOARD_SAMPLE_RATE_HZ;
  /* Fig. 4-14: a low-pass that removes the DAC's staircase harmonics while adding
   * little lag at the 745 Hz drive voltage (2nd-order Butterworth at 20 kHz: 3.0 deg at
   * 745 Hz, 6.1 deg at 1490 Hz; the staircase image at 50 kHz - 745 Hz is cut 16 dB). */
  cfg->recon_cutoff_hz = 20000.0;
  cfg->recon_q = 0.70710678118654752;
  for (int c = 0; c < DAC_NCH; c++) {
    cfg->gain[c] = 1.0;
    cfg->offset_v[c] = 0.0;
    cfg->initial_code[c] = (uint16_t)HAL_DAC_CODE_MID;
    cfg->modelled[c] = 1u;
  }
}

static int cfg_ok(const dac_cfg_t *c)
{
  if (!(isfinite(c->fs_hz) && c->fs_hz > 0.0 && c->fs_hz <= 1e7)) return 0;
  if (!(isfinite(c->recon_cutoff_hz) && c->recon_cutoff_hz >= 0.0 &&
        c->recon_cutoff_hz <= c->fs_hz))
    return 0;
  if (c->recon_cutoff_hz > 0.0 &&
      !(isfinite(c->recon_q) && c->recon_q >= 0.1 && c->recon_q <= 10.0))
    return 0;
  for (int i = 0; i < DAC_NCH; i++) {
    if (!(isfinite(c->gain[i]) && fabs(c->gain[i]) > 0.0 && fabs(c->gain[i]) <= 2.0)) return 0;
    if (!(isfinite(c->offset_v[i]) && fabs(c->offset_v[i]) <= (double)HAL_DAC_FULL_SCALE_V))
      return 0;
    if (c->initial_code[i] > HAL_DAC_CODE_MAX) return 0;
    if (c->modelled[i] > 1u) return 0;
  }
  return inl_check(&c->inl, DAC_BITS) == 0;
}

/* Inlined into dac_step's loops (called for every modelled channel every sample; a call
 * cost 2 % of a run's instructions when the loop became one over a channel list). */
static inline __attribute__((always_inline)) double held_level(dac_t *d, int c, uint16_t code)
{
  double u = d->scale[c] * (double)code + d->zero[c];
  if (d->inl[c].active) {
    if (d->inl_code[c] != code) {
      d->inl_code[c] = code;
      d->inl_v[c] = d->scale[c] * inl_lsb(&d->inl[c], (long)code);
    }
    u += d->inl_v[c];
  }
  if (d->ref_rel != 0.0) {
    const double off = d->cfg.offset_v[c];
    u = off + (u - off) * (1.0 + d->ref_rel);
  }
  return u;
}

void dac_set_ref(dac_t *d, double ref_rel) { d->ref_rel = ref_rel; }

/* Exact forms of the filter over one sample, in normalised time s = t / T. */
static int discretise(dac_forms_t *d, double w0, double fs_hz, double recon_q)
{
  const double T = 1.0 / fs_hz;
  const double wt = w0 * T;
  const double iq = 1.0 / recon_q;
  /* X = F T, F = [[A, B], [0, 0]], A = w0 [[0, 1], [-1, -1/Q]], B = w0 [0, 1]^T */
  double x[9] = {0.0, wt, 0.0, -wt, -wt * iq, wt, 0.0, 0.0, 0.0};
  double e[9];
  if (expm(3, x, e) != 0) return -1;
  d->ad[0][0] = e[0];
  d->ad[0][1] = e[1];
  d->ad[1][0] = e[3];
  d->ad[1][1] = e[4];
  d->bd[0] = e[2];
  d->bd[1] = e[5];

  /* exp([[X, I], [0, 0]]): top-right block = int_0^1 e^{X s} ds */
  double g[36], ge[36];
  memset(g, 0, sizeof g);
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) g[i * 6 + j] = x[i * 3 + j];
    g[i * 6 + 3 + i] = 1.0;
  }
  if (expm(6, g, ge) != 0) return -1;
  for (int j = 0; j < 3; j++) d->mv[j] = ge[0 * 6 + 3 + j]; /* h^T picks row 0 */

  /* Van Loan: exp([[-X^T, h h^T], [0, X]]) = [[., G], [0, E]], int = E^T G */
  memset(g, 0, sizeof g);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      g[i * 6 + j] = -x[j * 3 + i];
      g[(3 + i) * 6 + 3 + j] = x[i * 3 + j];
    }
  g[0 * 6 + 3] = 1.0; /* h h^T with h = e1 */
  if (expm(6, g, ge) != 0) return -1;
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++) s += ge[(3 + k) * 6 + 3 + i] * ge[k * 6 + 3 + j];
      d->msq[i][j] = s;
    }
  /* symmetrise against rounding */
  for (int i = 0; i < 3; i++)
    for (int j = i + 1; j < 3; j++) {
      const double m = 0.5 * (d->msq[i][j] + d->msq[j][i]);
      d->msq[i][j] = m;
      d->msq[j][i] = m;
    }
  d->q2[0] = d->msq[0][0];
  d->q2[1] = 2.0 * d->msq[0][1];
  d->q2[2] = 2.0 * d->msq[0][2];
  d->q2[3] = d->msq[1][1];
  d->q2[4] = 2.0 * d->msq[1][2];
  d->q2[5] = d->msq[2][2];
  return 0;
}

int dac_init(dac_t *d, const dac_cfg_t *cfg)
{
  if (d == NULL || cfg == NULL || !cfg_ok(cfg)) return -1;
  const int filtered = cfg->recon_cutoff_hz > 0.0;
  const double w0 = 2.0 * k_pi * cfg->recon_cutoff_hz;
  dac_forms_t form;
  memset(&form, 0, sizeof form);
  if (filtered && discretise(&form, w0, cfg->fs_hz, cfg->recon_q) != 0) return -1;
  /* nothing can fail from here on: built in place (cfg may be &d->cfg: copied first) */
  const dac_cfg_t c0 = *cfg;
  memset(d, 0, sizeof *d);
  d->cfg = c0;
  d->filtered = filtered;
  d->w0 = w0;
  d->form = form;
  const double lsb = 2.0 * (double)HAL_DAC_FULL_SCALE_V / 16384.0;
  for (int c = 0; c < DAC_NCH; c++) {
    d->scale[c] = c0.gain[c] * lsb;
    d->zero[c] = c0.offset_v[c] - c0.gain[c] * lsb * (double)HAL_DAC_CODE_MID;
  }
  for (int c = 0; c < DAC_NCH; c++) {
    (void)inl_init(&d->inl[c], &c0.inl, DAC_BITS, c0.inl_seed, DAC_RNG_STREAM_INL + (uint64_t)c);
    d->inl_code[c] = UINT32_MAX;
  }
  for (int c = 0; c < DAC_NCH; c++)
    if (c0.modelled[c]) d->on[d->n_on++] = (uint8_t)c;
  d->first_all = 1;
  for (int c = 0; c < DAC_FIRST; c++) d->first_all &= c0.modelled[c];
  for (int c = 0; c < DAC_NCH; c++) {
    d->latched[c] = c0.initial_code[c];
    d->pending[c] = c0.initial_code[c];
    d->x[c][0] = held_level(d, c, c0.initial_code[c]);
    d->x[c][1] = 0.0;
  }
  return 0;
}

int dac_write(dac_t *d, const hal_dac_frame_t *frame)
{
  if (d == NULL || frame == NULL) return -1;
  /* HAL_DAC_CODE_MAX is all ones below bit 14, so some code exceeds it exactly when the OR
   * of all codes does: one test for the frame (the compiler makes the OR one vector
   * operation), not a branch per channel, every sample */
  _Static_assert((HAL_DAC_CODE_MAX & (HAL_DAC_CODE_MAX + 1u)) == 0u, "CODE_MAX = 2^n - 1");
  uint16_t any = 0u;
  for (int c = 0; c < DAC_NCH; c++) any = (uint16_t)(any | frame->code[c]);
  if (any > HAL_DAC_CODE_MAX) return -1;
  memcpy(d->pending, frame->code, sizeof d->pending);
  return 0;
}

/* Codes of every channel move to the held ones (the unmodelled too: their codes stay
 * what the board would hold). */
static void latch(dac_t *d)
{
  for (int c = 0; c < DAC_NCH; c++) d->latched[c] = d->pending[c];
}

/* One channel's sample, staircase alone (no reconstruction filter). */
static inline __attribute__((always_inline)) void step_held(dac_t *d, int c, dac_out_t *out)
{
  dac_chan_out_t *o = &out->ch[c];
  const double u = held_level(d, c, d->latched[c]);
  o->held_v = u;
  o->mean_v = u;
  o->mean_sq_v2 = u * u;
  o->end_v = u;
  o->end_dvdt_v_per_s = 0.0;
}

/* One channel's sample through the reconstruction filter (the header's exact forms). */
static inline __attribute__((always_inline)) void step_filtered(dac_t *d, int c, dac_out_t *out)
{
  const dac_forms_t *f = &d->form;
  const double *q = f->q2;
  dac_chan_out_t *o = &out->ch[c];
  const double u = held_level(d, c, d->latched[c]);
  const double z0 = d->x[c][0], z1 = d->x[c][1];
  o->held_v = u;
  o->mean_v = f->mv[0] * z0 + f->mv[1] * z1 + f->mv[2] * u;
  o->mean_sq_v2 = z0 * (q[0] * z0 + q[1] * z1 + q[2] * u) + z1 * (q[3] * z1 + q[4] * u) +
                  q[5] * u * u;
  const double n0 = f->ad[0][0] * z0 + f->ad[0][1] * z1 + f->bd[0] * u;
  const double n1 = f->ad[1][0] * z0 + f->ad[1][1] * z1 + f->bd[1] * u;
  d->x[c][0] = n0;
  d->x[c][1] = n1;
  o->end_v = n0;
  o->end_dvdt_v_per_s = d->w0 * n1;
}

/* The modelled channels: the first converter's four by a loop of constant count when all
 * four are modelled (the compiler unrolls it: a loop over the channel list instead cost
 * 60 instructions a sample), then the rest of the list. */
void dac_step(dac_t *d, dac_out_t *out)
{
  int i = 0;
  if (!d->filtered) {
    if (d->first_all) {
      for (int c = 0; c < DAC_FIRST; c++) step_held(d, c, out);
      i = DAC_FIRST;
    }
    for (; i < d->n_on; i++) step_held(d, d->on[i], out);
  } else {
    if (d->first_all) {
      for (int c = 0; c < DAC_FIRST; c++) step_filtered(d, c, out);
      i = DAC_FIRST;
    }
    for (; i < d->n_on; i++) step_filtered(d, d->on[i], out);
  }
  latch(d);
}
