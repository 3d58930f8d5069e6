#include "plant/thermal.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "plant/expm.h"

/* Presets. None of these is measured in the thesis (it gives no thermal time
 * constants); they are plausible sizes for a packaged MEMS head on a small pickoff
 * board, wired to a DSP board, cooling in still air after a heat-gun blast (§7.3.2:
 * from 62 to 36 degC over several hundred seconds):
 *  - default: the ring-diode preamplifier sits next to the head (it must, to keep the
 *    pickoff capacitances small), so structure and circuit exchange heat in about a
 *    minute; the board sensor is on the DSP board, coupled to the pickoff board only
 *    through connectors and air (15 min) and warmed 5 K by the DSP and regulators.
 *  - tight: every pair exchanges heat in 10 s: all three read the same temperature
 *    to within the self-heating offsets, and a board sensor is as good as any.
 *  - loose: the three nodes follow the ambient independently (pair exchange 5.5 h)
 *    with very different time constants (15, 4 and 2 min). */
void thermal_preset(thermal_cfg_t *cfg, thermal_preset_t which)
{
  memset(cfg, 0, sizeof(*cfg));
  cfg->dt_s = 1e-3;
  cfg->tau_s[THERMAL_STRUCT] = 400.0;
  cfg->tau_s[THERMAL_CIRCUIT] = 300.0;
  cfg->tau_s[THERMAL_BOARD] = 180.0;
  cfg->rise_k[THERMAL_STRUCT] = 0.0;
  cfg->rise_k[THERMAL_CIRCUIT] = 1.5;
  cfg->rise_k[THERMAL_BOARD] = 5.0;
  switch (which) {
  case THERMAL_PRESET_TIGHT:
    cfg->couple_per_s[THERMAL_PAIR_SC] = 0.1;
    cfg->couple_per_s[THERMAL_PAIR_SB] = 0.1;
    cfg->couple_per_s[THERMAL_PAIR_CB] = 0.1;
    break;
  case THERMAL_PRESET_LOOSE:
    cfg->tau_s[THERMAL_STRUCT] = 900.0;
    cfg->tau_s[THERMAL_CIRCUIT] = 250.0;
    cfg->tau_s[THERMAL_BOARD] = 120.0;
    cfg->couple_per_s[THERMAL_PAIR_SC] = 5e-5;
    cfg->couple_per_s[THERMAL_PAIR_SB] = 5e-5;
    cfg->couple_per_s[THERMAL_PAIR_CB] = 5e-5;
    break;
  case THERMAL_PRESET_DEFAULT:
  default:
    cfg->couple_per_s[THERMAL_PAIR_SC] = 1.0 / 60.0;
    cfg->couple_per_s[THERMAL_PAIR_SB] = 0.0;
    cfg->couple_per_s[THERMAL_PAIR_CB] = 1.0 / 900.0;
    break;
  }
}

void thermal_default_cfg(thermal_cfg_t *cfg) { thermal_preset(cfg, THERMAL_PRESET_DEFAULT); }

static int finite_in(double v, double lo, double hi)
{
  return isfinite(v) && v >= lo && v <= hi;
}

int thermal_cfg_check(const thermal_cfg_t *c, const char **key)
{
  static const char *const tau_keys[THERMAL_NODES] = {"tau_s[0]", "tau_s[1]", "tau_s[2]"};
  static const char *const g_keys[THERMAL_NODES] = {"couple_per_s[0]", "couple_per_s[1]",
                                                    "couple_per_s[2]"};
  static const char *const r_keys[THERMAL_NODES] = {"rise_k[0]", "rise_k[1]", "rise_k[2]"};
  const char *bad = NULL;
  if (c == NULL) bad = "cfg";
  else if (!finite_in(c->dt_s, 1e-6, 3600.0)) bad = "dt_s";
  for (int i = 0; bad == NULL && i < THERMAL_NODES; i++) {
    if (!finite_in(c->tau_s[i], 1e-3, 1e9)) bad = tau_keys[i];
    else if (!finite_in(c->couple_per_s[i], 0.0, 1e3)) bad = g_keys[i];
    else if (!finite_in(c->rise_k[i], -100.0, 500.0)) bad = r_keys[i];
  }
  if (key != NULL) *key = bad;
  return bad == NULL ? 0 : -1;
}

/* L = diag(1/tau) + Laplacian(g); b = 1/tau; h = rise/tau. */
static void network(const thermal_cfg_t *c, double l[3][3], double b[3], double h[3])
{
  const double g_sc = c->couple_per_s[THERMAL_PAIR_SC];
  const double g_sb = c->couple_per_s[THERMAL_PAIR_SB];
  const double g_cb = c->couple_per_s[THERMAL_PAIR_CB];
  const double g[3][3] = {{0.0, g_sc, g_sb}, {g_sc, 0.0, g_cb}, {g_sb, g_cb, 0.0}};
  for (int i = 0; i < 3; i++) {
    b[i] = 1.0 / c->tau_s[i];
    h[i] = c->rise_k[i] / c->tau_s[i];
    double sum = 0.0;
    for (int j = 0; j < 3; j++) {
      l[i][j] = -g[i][j];
      sum += g[i][j];
    }
    l[i][i] = b[i] + sum;
  }
}

void thermal_steady(const thermal_cfg_t *cfg, double ambient_k, double t_k[THERMAL_NODES])
{
  double l[3][3], b[3], h[3], r[3];
  network(cfg, l, b, h);
  for (int i = 0; i < 3; i++) r[i] = b[i] * ambient_k + h[i];
  /* Cramer's rule; L is diagonally dominant, det > 0 */
  const double det = l[0][0] * (l[1][1] * l[2][2] - l[1][2] * l[2][1]) -
                     l[0][1] * (l[1][0] * l[2][2] - l[1][2] * l[2][0]) +
                     l[0][2] * (l[1][0] * l[2][1] - l[1][1] * l[2][0]);
  for (int k = 0; k < 3; k++) {
    double m[3][3];
    memcpy(m, l, sizeof m);
    for (int i = 0; i < 3; i++) m[i][k] = r[i];
    t_k[k] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
              m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
              m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) /
             det;
  }
}

int thermal_init(thermal_t *th, const thermal_cfg_t *cfg, double ambient_k)
{
  if (th == NULL || thermal_cfg_check(cfg, NULL) != 0) return -1;
  if (!finite_in(ambient_k, 1.0, 2000.0)) return -1;
  double l[3][3], b[3], h[3];
  network(cfg, l, b, h);
  /* Gam = int_0^dt exp(-L s) ds from exp([-L I; 0 0] dt) (top-right block); then
   * Phi - I = -L Gam and g_h = Gam h without the cancellation of expm(.) - I. */
  double aug[36] = {0.0}, e[36];
  for (int i = 0; i < 3; i++) {
    for (int j = 0; j < 3; j++) aug[i * 6 + j] = -l[i][j] * cfg->dt_s;
    aug[i * 6 + 3 + i] = cfg->dt_s;
  }
  if (expm(6, aug, e) != 0) return -2;
  thermal_t tmp;
  memset(&tmp, 0, sizeof tmp);
  tmp.cfg = *cfg;
  for (int i = 0; i < 3; i++) {
    tmp.g_heat[i] = 0.0;
    for (int j = 0; j < 3; j++) {
      double s = 0.0;
      for (int k = 0; k < 3; k++) s -= l[i][k] * e[k * 6 + 3 + j];
      tmp.dphi[i][j] = s;
      tmp.g_heat[i] += e[i * 6 + 3 + j] * h[j];
    }
  }
  thermal_steady(cfg, ambient_k, tmp.t_k);
  *th = tmp;
  return 0;
}

int thermal_init_cold(thermal_t *th, const thermal_cfg_t *cfg, double ambient_k)
{
  const int rc = thermal_init(th, cfg, ambient_k);
  if (rc != 0) return rc;
  for (int i = 0; i < THERMAL_NODES; i++) th->t_k[i] = ambient_k;
  return 0;
}

int thermal_step(thermal_t *th, double ambient_k)
{
  if (!isfinite(ambient_k)) return -1;
  /* T(k+1) = T + (Phi - I)(T - Ta) + g_h: since Phi 1 + g_a = 1 (a uniform ambient
   * is an equilibrium without heating), this equals Phi T + g_a Ta + g_h, but only
   * small increments are rounded against the 300 K state. */
  double d[3], inc[3];
  for (int j = 0; j < 3; j++) d[j] = th->t_k[j] - ambient_k;
  for (int i = 0; i < 3; i++)
    inc[i] = th->dphi[i][0] * d[0] + th->dphi[i][1] * d[1] + th->dphi[i][2] * d[2] +
             th->g_heat[i];
  for (int i = 0; i < 3; i++) th->t_k[i] += inc[i];
  return 0;
}

double thermal_temp(const thermal_t *th, int node)
{
  if (node < 0 || node >= THERMAL_NODES) return NAN;
  return th->t_k[node];
}

void thermal_set(thermal_t *th, const double t_k[THERMAL_NODES])
{
  for (int i = 0; i < THERMAL_NODES; i++)
    if (isfinite(t_k[i])) th->t_k[i] = t_k[i];
}
