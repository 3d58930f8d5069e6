#include "plant/mech.h"

#include <math.h>
#include <stddef.h>
#include <string.h>
#include "plant/plant_const.h"
#include "plant/qlaw.h"
#include "board.h"

static const double kPi = PLANT_PI;

#define NA (MECH_NS + MECH_NU) /* augmented [state; input] size */

/* Monomials of the truncated algebra, exponents of (w, a, e). The set is closed under
 * taking divisors, so the monomials outside it span an ideal and truncation is an
 * algebra homomorphism. Order: blocks with the same power of w are contiguous. */
static const int kMono[MECH_NMONO][3] = {{0, 0, 0}, {0, 0, 1}, {0, 0, 2},  /* 1, e, e^2     */
                                         {1, 0, 0}, {1, 0, 1}, {1, 0, 2},  /* w, we, we^2   */
                                         {2, 0, 0}, {2, 0, 1},             /* w^2, w^2 e    */
                                         {3, 0, 0},                        /* w^3           */
                                         {0, 1, 0}, {1, 1, 0}, {0, 1, 1}}; /* a, w a, a e   */

static int mono_index(int pw, int pa, int pe)
{
  for (int i = 0; i < MECH_NMONO; i++)
    if (kMono[i][0] == pw && kMono[i][1] == pa && kMono[i][2] == pe) return i;
  return -1; /* in the ideal: truncated */
}

void mech_default_cfg(mech_cfg_t *cfg)
{
  memset(cfg, 0, sizeof(*cfg));
  cfg->f1_hz = 1489.9; /* §7.2.2 sweep */
  cfg->q1 = 33.33;     /* §7.2.2, -3 dB points */
  cfg->f2_hz = 2000.0; /* design, §2.4.2 */
  cfg->q2 = 3.0;       /* design, §2.2.2 (air) */
  cfg->temp_ref_k = 298.15;
  cfg->ket_per_k = 40e-6; /* (2-29) range 25..75 ppm/K; table 7-4 fits 40 (plant_cfg.c) */
  cfg->kq_per_s2 = 0.0;
  cfg->dq_per_s = 0.0;
  cfg->mass_kg = 0.26e-6;                    /* §4.6.1: 0.26 mg */
  cfg->fs_hz = (double)BOARD_SAMPLE_RATE_HZ; /* §4.4.2 */
  /* Measured (test_mech, test_refresh_threshold_error): with e expanded to second
   * order the steady-state error of the drive at resonance (Q1 = 33) is about
   * 860 e^3 (8.6e-10 at e = 1e-3, 6.9e-9 at 2e-3). 1e-3 keeps it 100x below 1e-7 and
   * is 50 K at 40 ppm/K: a refresh (one exponential in the truncated algebra) at most
   * once or twice in a whole chamber run. */
  cfg->refresh_eps = 1e-3;
  cfg->full_kinematics = 1;
  cfg->brownian = 1;
  /* Q constant, no cubic stiffness, no electrostatic softening (memset) */
}

static int finite_in(double v, double lo, double hi)
{
  return isfinite(v) && v >= lo && v <= hi;
}

int mech_cfg_check(const mech_cfg_t *c, const char **key)
{
  const char *bad = NULL;
  if (c == NULL) bad = "cfg";
  else if (!finite_in(c->fs_hz, 1e3, 1e7)) bad = "fs_hz";
  else if (!finite_in(c->f1_hz, 1.0, 0.45 * c->fs_hz)) bad = "f1_hz";
  else if (!finite_in(c->q1, 0.5, 1e6)) bad = "q1";
  else if (!finite_in(c->f2_hz, 1.0, 0.45 * c->fs_hz)) bad = "f2_hz";
  else if (!finite_in(c->q2, 0.5, 1e6)) bad = "q2";
  else if (!finite_in(c->temp_ref_k, 1.0, 1000.0)) bad = "temp_ref_k";
  else if (!finite_in(c->ket_per_k, -1e-3, 1e-3)) bad = "ket_per_k";
  else if (!finite_in(c->kq_per_s2, -1e9, 1e9)) bad = "kq_per_s2";
  else if (!finite_in(c->dq_per_s, -1e4, 1e4)) bad = "dq_per_s";
  else if (!finite_in(c->mass_kg, 1e-12, 1.0)) bad = "mass_kg";
  else if (!finite_in(c->refresh_eps, 1e-9, 1e-2)) bad = "refresh_eps";
  else if (!finite_in(c->k3_drive_per_m2, -1e12, 1e12)) bad = "k3_drive_per_m2";
  else if (!finite_in(c->k3_sense_per_m2, -1e12, 1e12)) bad = "k3_sense_per_m2";
  else if (!finite_in(c->nl_damp_drive_per_m2, 0.0, 1e12)) bad = "nl_damp_drive_per_m2";
  /* softening below half the sense stiffness at T0: far from pull-in over (2-32)'s range */
  else if (!finite_in(c->ke2_per_s2, 0.0, 0.5 * (2.0 * kPi * c->f2_hz) * (2.0 * kPi * c->f2_hz)))
    bad = "ke2_per_s2";
  else if (c->q_law < 0 || c->q_law >= QLAW_NLAWS) bad = "q_law";
  else if (c->full_kinematics != 0 && c->full_kinematics != 1) bad = "full_kinematics";
  else if (c->brownian != 0 && c->brownian != 1) bad = "brownian";
  if (key != NULL) *key = bad;
  return bad == NULL ? 0 : -1;
}

/* (2-32): wn(T) = wn(T0) (1 - 0.5 kET (T - T0)). */
static double wn_at(const mech_cfg_t *c, double f_hz, double temp_k)
{
  return 2.0 * kPi * f_hz * (1.0 - 0.5 * c->ket_per_k * (temp_k - c->temp_ref_k));
}

static int temp_ok(const mech_cfg_t *c, double temp_k)
{
  /* keep (2-32) meaningful: the linear law must not drive wn towards zero */
  return isfinite(temp_k) && temp_k > 0.0 && temp_k < 2000.0 &&
         fabs(0.5 * c->ket_per_k * (temp_k - c->temp_ref_k)) < 0.2;
}

double mech_temp_clamp(const mech_cfg_t *c, double temp_k, int *outside)
{
  /* the edge of temp_ok's range, a hair inside: |0.5 kET dT| <= 0.199, 1..1999 K */
  double lo = 1.0, hi = 1999.0;
  if (c->ket_per_k != 0.0) {
    const double span = 0.398 / fabs(c->ket_per_k);
    if (c->temp_ref_k - span > lo) lo = c->temp_ref_k - span;
    if (c->temp_ref_k + span < hi) hi = c->temp_ref_k + span;
  }
  int out = 1;
  double v = temp_k;
  if (!isfinite(v)) v = c->temp_ref_k;
  else if (v < lo) v = lo;
  else if (v > hi) v = hi;
  else out = 0;
  if (outside != NULL) *outside = out;
  return v;
}

enum {
  MONO_1 = 0,
  MONO_E,
  MONO_E2,
  MONO_W,
  MONO_WE,
  MONO_WE2,
  MONO_W2,
  MONO_W2E,
  MONO_W3,
  MONO_A,
  MONO_WA,
  MONO_AE
};

/* Q of resonance i (0 drive, 1 sense) at temp_k by the law; *out set when the law was
 * held at its edge. QLAW_CONST gives the configured Q itself. */
static double q_at(const mech_cfg_t *c, int i, double temp_k, int *out)
{
  const double q0 = i == 0 ? c->q1 : c->q2;
  *out = 0;
  if (c->q_law == QLAW_CONST) return q0;
  const double wn_ratio = 1.0 - 0.5 * c->ket_per_k * (temp_k - c->temp_ref_k); /* (2-32) */
  return q0 * qlaw_factor(c->q_law, temp_k, c->temp_ref_k, wn_ratio, out);
}

/* Continuous generator in scaled coordinates, one block per monomial: A(w,a,e) =
 * wr * sum_m Ahat_m * mono_m, augmented with the input columns. Only the four state
 * rows are stored: the input rows of [A B; 0 0] are zero. The generator is exactly
 * polynomial in (w, a, e): stiffness r^2 (1+e)^2, damping r (1+e) / Q (Q of the
 * temperature the blocks are made at), Coriolis and Euler linear, centrifugal quadratic;
 * the electrostatic softening and the electrodes' stiffness elec = {k_yx, k_e} at the
 * discretisation (mech.h) are constant stiffnesses. */
static void build_generator(const mech_cfg_t *c, double wr, double wn1, double wn2,
                            const double q[2], const double elec[2],
                            double ahat[MECH_NMONO][MECH_NS][NA])
{
  const double r1 = wn1 / wr, r2 = wn2 / wr;
  const double q1 = q[0], q2 = q[1];
  /* cross couplings follow the structure temperature like the resonances: stiffness with
   * wn^2, damping with wn (Q constant) */
  const double s = wn1 / wn_at(c, c->f1_hz, c->temp_ref_k);
  const double kq = c->kq_per_s2 * s * s / (wr * wr);
  const double dq = c->dq_per_s * s / wr;
  memset(ahat, 0, sizeof(double) * MECH_NMONO * MECH_NS * NA);
  double(*a0)[NA] = ahat[MONO_1];
  a0[0][1] = 1.0;
  a0[1][0] = -r1 * r1;
  a0[1][1] = -r1 / q1;
  a0[1][4] = 1.0;
  a0[2][3] = 1.0;
  a0[3][0] = -kq;
  if (elec[0] != 0.0) a0[3][0] -= elec[0] / (wr * wr); /* nulling electrodes' coupling */
  a0[3][1] = -dq;
  a0[3][2] = -r2 * r2;
  if (c->ke2_per_s2 != 0.0) a0[3][2] += c->ke2_per_s2 / (wr * wr); /* (6-3): softening */
  if (elec[1] != 0.0) a0[3][2] += elec[1] / (wr * wr);             /* electrodes' softening */
  a0[3][3] = -r2 / q2;
  a0[3][5] = 1.0;
  /* e: wn -> wn (1 + e) */
  ahat[MONO_E][1][0] = -2.0 * r1 * r1;
  ahat[MONO_E][1][1] = -r1 / q1;
  ahat[MONO_E][3][0] = -2.0 * kq;
  ahat[MONO_E][3][1] = -dq;
  ahat[MONO_E][3][2] = -2.0 * r2 * r2;
  ahat[MONO_E][3][3] = -r2 / q2;
  ahat[MONO_E2][1][0] = -r1 * r1;
  ahat[MONO_E2][3][0] = -kq;
  ahat[MONO_E2][3][2] = -r2 * r2;
  /* w: Coriolis 2 Omega y' on the sense axis, (2-22) */
  ahat[MONO_W][3][1] = 2.0;
  if (c->full_kinematics) {
    ahat[MONO_W][1][3] = -2.0; /* reciprocal Coriolis on the drive axis, (2-20) */
    ahat[MONO_W2][1][0] = 1.0; /* centrifugal Omega^2 y, (2-20) */
    ahat[MONO_W2][3][2] = 1.0; /* centrifugal Omega^2 x */
    ahat[MONO_A][3][0] = 1.0;  /* Euler force +alpha y on the sense axis */
    ahat[MONO_A][1][2] = -1.0; /* Euler force -alpha x on the drive axis */
  }
}

/* Arithmetic in the truncated algebra. An element X = sum_i mono_i X_i has one 6x6
 * block per monomial; (XY)_i = sum over (g, j) with mono_g mono_j = mono_i of X_g Y_j.
 * Every element used here has input rows [0 I] in the unit block and zero elsewhere
 * (exp of [A B; 0 0] and its Taylor partial sums), so only the four state rows are
 * stored: the state rows of X_g Y_j are X_g[:, 0:4] Y_j[0:4, :] plus, for j = unit,
 * X_g[:, 4:6] in the input columns.
 *
 * kMono lists every monomial after its divisors, so block i of a product needs only
 * blocks <= i of either factor: computing the blocks from the last to the first lets
 * the product overwrite its right factor (and the left one, when squaring). */
typedef double alg_t[MECH_NMONO][MECH_NS][NA];

/* y <- c0 * 1 + scale * (x y), in place in y; x may be y. */
static void alg_mul_acc(const alg_t x, alg_t y, double c0, double scale)
{
  for (int i = MECH_NMONO - 1; i >= 0; i--) {
    double t[MECH_NS][NA] = {{0.0}};
    for (int g = 0; g <= i; g++) {
      for (int j = 0; j <= i; j++) {
        if (mono_index(kMono[g][0] + kMono[j][0], kMono[g][1] + kMono[j][1],
                       kMono[g][2] + kMono[j][2]) != i)
          continue;
        for (int r = 0; r < MECH_NS; r++) {
          for (int k = 0; k < MECH_NS; k++) {
            const double xrk = x[g][r][k];
            if (xrk == 0.0) continue; /* the generator is mostly zero */
            for (int q = 0; q < NA; q++) t[r][q] += xrk * y[j][k][q];
          }
          if (j == MONO_1)
            for (int q = MECH_NS; q < NA; q++) t[r][q] += x[g][r][q];
        }
      }
    }
    for (int r = 0; r < MECH_NS; r++)
      for (int q = 0; q < NA; q++) y[i][r][q] = scale * t[r][q];
    if (i == MONO_1)
      for (int r = 0; r < MECH_NS; r++) y[i][r][r] += c0;
  }
}

/* Norm of an element: sum over the blocks of the 1-norm of the full 6x6 block (the
 * input rows of a generator are zero). Submultiplicative for the product above (each
 * block product is bounded by the product of the norms, truncation only drops terms),
 * and an upper bound of the 1-norm of the 72x72 left-regular representation. */
static double alg_norm(const alg_t x)
{
  double s = 0.0;
  for (int i = 0; i < MECH_NMONO; i++) {
    double best = 0.0;
    for (int q = 0; q < NA; q++) {
      double col = 0.0;
      for (int r = 0; r < MECH_NS; r++) col += fabs(x[i][r][q]);
      best = fmax(best, col);
    }
    s += best;
  }
  return s;
}

/* e = exp(b) in the algebra (b: generator, zero input rows; overwritten by its scaled
 * copy). Scaling and squaring: b / 2^s with norm <= 1/2, Taylor to degree 18 by
 * Horner (remainder below 0.5^19 / 19! = 1.6e-23 of the norm, and the series
 * converges in the algebra because the norm is submultiplicative), then s squarings.
 * Returns -1 for a non-finite generator (e untouched). */
static int alg_exp(alg_t b, alg_t e)
{
  enum { kDegree = 18 };
  const double nrm = alg_norm(b);
  if (!isfinite(nrm)) return -1;
  int s = 0;
  if (nrm > 0.5) s = (int)ceil(log2(nrm / 0.5));
  const double scale = ldexp(1.0, -s);
  for (int i = 0; i < MECH_NMONO; i++)
    for (int r = 0; r < MECH_NS; r++)
      for (int q = 0; q < NA; q++) b[i][r][q] *= scale;
  /* Horner: e = 1 + b/1 (1 + b/2 (1 + ... (1 + b/18))) */
  for (int i = 0; i < MECH_NMONO; i++)
    for (int r = 0; r < MECH_NS; r++)
      for (int q = 0; q < NA; q++) e[i][r][q] = b[i][r][q] / kDegree;
  for (int r = 0; r < MECH_NS; r++) e[MONO_1][r][r] += 1.0;
  for (int k = kDegree - 1; k >= 1; k--) alg_mul_acc(b, e, 1.0, 1.0 / k);
  for (int k = 0; k < s; k++) alg_mul_acc(e, e, 0.0, 1.0);
  return 0;
}

/* Taylor blocks at structure temperature temp_k (e = 0 there) and quality factors q:
 * exp(h A) in the truncated algebra is sum_i mono_i P_i, the P_i being the blocks
 * [Phi Gamma]. Returns -2 (blk untouched) for a non-finite generator. */
static int discretise_blocks(const mech_cfg_t *c, double wr, double temp_k, double clock,
                             const double qual[2], const double elec[2], alg_t blk)
{
  const double wn1 = clock * wn_at(c, c->f1_hz, temp_k);
  const double wn2 = clock * wn_at(c, c->f2_hz, temp_k);
  const double h = wr / c->fs_hz;

  alg_t ahat; /* 2.3 kB: the only scratch */
  build_generator(c, wr, wn1, wn2, qual, elec, ahat);
  for (int i = 0; i < MECH_NMONO; i++)
    for (int r = 0; r < MECH_NS; r++)
      for (int q = 0; q < NA; q++) ahat[i][r][q] *= h;
  return alg_exp(ahat, blk) != 0 ? -2 : 0;
}

/* Re-discretise at temp_k with the Q of m->q_now; m unchanged on failure. */
static int discretise(mech_t *m, double temp_k)
{
  if (discretise_blocks(&m->cfg, m->wr, temp_k, m->clock, m->q_now, m->elec_disc, m->blk) != 0)
    return -2;
  m->temp_disc_k = temp_k;
  m->clock_disc = m->clock;
  m->q_disc[0] = m->q_now[0];
  m->q_disc[1] = m->q_now[1];
  m->eps = 0.0;
  m->q_valid = 0;
  m->refresh_count++;
  return 0;
}

static void update_noise(mech_t *m)
{
  const mech_cfg_t *c = &m->cfg;
  for (int i = 0; i < MECH_NU; i++) {
    /* held sequence variance S fs / 2; scaled input u / wr^2 */
    const double s = c->brownian ? sqrt(mech_noise_psd(m, i + 1) * c->fs_hz * 0.5) : 0.0;
    m->noise_sd[i] = s / (m->wr * m->wr);
  }
}

int mech_init(mech_t *m, const mech_cfg_t *cfg, double temp_k, uint64_t seed)
{
  if (m == NULL || mech_cfg_check(cfg, NULL) != 0 || !temp_ok(cfg, temp_k)) return -1;
  /* built in place: the only step that can fail (the exponential) writes m->blk alone
   * and only on success; cfg is copied first in case it lives inside m */
  const mech_cfg_t c = *cfg;
  const double wr = 2.0 * kPi * c.f1_hz;
  int out[2];
  const double q[2] = {q_at(&c, 0, temp_k, &out[0]), q_at(&c, 1, temp_k, &out[1])};
  const double no_elec[2] = {0.0, 0.0};
  if (discretise_blocks(&c, wr, temp_k, 1.0, q, no_elec, m->blk) != 0) return -2;
  m->cfg = c;
  m->clock = m->clock_disc = 1.0;
  for (int i = 0; i < 2; i++) m->q_now[i] = m->q_disc[i] = q[i];
  m->q_out = (out[0] || out[1]) ? MECH_OUT_Q : 0u;
  m->duffing_out = 0u;
  m->drift_kq_per_s2 = m->drift_dq_per_s = 0.0;
  m->elec_kyx_per_s2 = m->elec_ke_per_s2 = 0.0;
  m->elec_disc[0] = m->elec_disc[1] = m->elec_sum[0] = m->elec_sum[1] = 0.0;
  m->elec_n = 0;
  m->elec_on = 0;
  m->held = c.k3_drive_per_m2 != 0.0 || c.k3_sense_per_m2 != 0.0 || c.nl_damp_drive_per_m2 != 0.0;
  m->wr = wr;
  m->temp_k = temp_k;
  m->temp_disc_k = temp_k;
  m->eps = 0.0;
  memset(m->q, 0, sizeof m->q);
  memset(m->qmax, 0, sizeof m->qmax);
  memset(m->k, 0, sizeof m->k);
  m->coef[0] = m->coef[1] = 0.0;
  m->q_valid = 0;
  m->k_valid = 0;
  memset(m->z, 0, sizeof m->z);
  m->refresh_count = 0;
  rng_seed(&m->rng[0], seed, MECH_RNG_STREAM_DRIVE);
  rng_seed(&m->rng[1], seed, MECH_RNG_STREAM_SENSE);
  update_noise(m);
  return 0;
}

/* The Q law at temp_k into m->q_now; 1 when either moved by refresh_eps from the blocks'. */
static int update_q(mech_t *m, double temp_k)
{
  if (m->cfg.q_law == QLAW_CONST) return 0;
  int out[2];
  for (int i = 0; i < 2; i++) m->q_now[i] = q_at(&m->cfg, i, temp_k, &out[i]);
  m->q_out = (out[0] || out[1]) ? MECH_OUT_Q : 0u;
  return fabs(m->q_now[0] / m->q_disc[0] - 1.0) > m->cfg.refresh_eps ||
         fabs(m->q_now[1] / m->q_disc[1] - 1.0) > m->cfg.refresh_eps;
}

/* The blocks' e for the present temperature and clock; re-discretised when it (or Q)
 * moved by refresh_eps. */
static int rescale(mech_t *m, int q_moved)
{
  const double e = m->clock * wn_at(&m->cfg, 1.0, m->temp_k) /
                       (m->clock_disc * wn_at(&m->cfg, 1.0, m->temp_disc_k)) -
                   1.0;
  if (fabs(e) > m->cfg.refresh_eps || q_moved) {
    if (discretise(m, m->temp_k) != 0) {
      /* cannot happen for a validated cfg (discretise fails before it writes
       * anything); stay on the old blocks */
      m->eps = e;
      m->q_valid = 0;
      return -2;
    }
  } else {
    m->eps = e;
    m->q_valid = 0;
  }
  update_noise(m);
  return 0;
}

int mech_set_temp(mech_t *m, double temp_k)
{
  if (!temp_ok(&m->cfg, temp_k)) return -1;
  if (temp_k == m->temp_k) return 0;
  m->temp_k = temp_k;
  return rescale(m, update_q(m, temp_k));
}

int mech_set_clock(mech_t *m, double clock)
{
  if (!(isfinite(clock) && clock > 0.5 && clock < 2.0)) return -1;
  if (clock == m->clock) return 0;
  m->clock = clock;
  return rescale(m, 0);
}

/* Collapse the temperature powers at the current e: q[p][r] = sum over the blocks of
 * w^p a^r e^k of e^k P. Done when e changes (at most once per thermal update). */
static void build_q(mech_t *m)
{
  const double e = m->eps;
  const double ep[3] = {1.0, e, e * e};
  memset(m->q, 0, sizeof(m->q));
  for (int i = 0; i < MECH_NMONO; i++) {
    const double c = ep[kMono[i][2]];
    double(*dst)[NA] = m->q[kMono[i][0]][kMono[i][1]];
    for (int r = 0; r < MECH_NS; r++)
      for (int q = 0; q < NA; q++) dst[r][q] += c * m->blk[i][r][q];
  }
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 2; j++) {
      double mx = 0.0;
      for (int r = 0; r < MECH_NS; r++)
        for (int q = 0; q < NA; q++) mx = fmax(mx, fabs(m->q[i][j][r][q]));
      m->qmax[i][j] = mx;
    }
  m->q_valid = 1;
  m->k_valid = 0;
}

/* K = q00 + w (q10 + w (q20 + w q30)) + a (q01 + w q11): when the rate changes. Terms
 * whose contribution per sample is below 1e-14 of the state are left out (the w^3
 * term below about 250 deg/s, everything of a when the rate does not accelerate, all
 * of (2-20) when full_kinematics is off): that keeps the per-sample error far under
 * the 1e-9 of the expansion itself. */
static void build_k(mech_t *m, double w, double a)
{
  const double kTiny = 1e-14;
  const int use_w3 = fabs(w * w * w) * m->qmax[3][0] > kTiny;
  const int use_w2 = use_w3 || w * w * m->qmax[2][0] > kTiny;
  const int use_a = fabs(a) * m->qmax[0][1] > kTiny;
  const int use_wa = fabs(a * w) * m->qmax[1][1] > kTiny;
  const double *q00 = &m->q[0][0][0][0], *q10 = &m->q[1][0][0][0], *q20 = &m->q[2][0][0][0];
  const double *q30 = &m->q[3][0][0][0], *q01 = &m->q[0][1][0][0], *q11 = &m->q[1][1][0][0];
  double *k = &m->k[0][0];
  enum { NK = MECH_NS * NA };
  if (use_w3)
    for (int i = 0; i < NK; i++) k[i] = q00[i] + w * (q10[i] + w * (q20[i] + w * q30[i]));
  else if (use_w2)
    for (int i = 0; i < NK; i++) k[i] = q00[i] + w * (q10[i] + w * q20[i]);
  else
    for (int i = 0; i < NK; i++) k[i] = q00[i] + w * q10[i];
  if (use_a)
    for (int i = 0; i < NK; i++) k[i] += a * q01[i];
  if (use_wa)
    for (int i = 0; i < NK; i++) k[i] += a * w * q11[i];
  m->coef[0] = w;
  m->coef[1] = a;
  m->k_valid = 1;
}

/* The cubic term k3 u^3 of a restoring force, u held to |k3| u^2 <= MECH_DUFFING_MAX
 * (flag set then). */
static double cubic(double k3, double u, unsigned flag, unsigned *out)
{
  const double lim2 = MECH_DUFFING_MAX / fabs(k3);
  if (u * u > lim2) {
    u = u > 0.0 ? sqrt(lim2) : -sqrt(lim2);
    *out |= flag;
  }
  return k3 * u * u * u;
}

/* The held forces of mech.h (Duffing, nonlinear drive damping, coupling drift, electrode
 * stiffness) per unit mass, from the motion at
 * the middle of the sample: the cubic Hermite interpolant of the states at its start (z0)
 * and end without these forces (z1), scaled units (mech.h). */
static void held_forces(mech_t *m, const double *z0, const double *z1, double *fy, double *fx)
{
  const mech_cfg_t *c = &m->cfg;
  const double T = 1.0 / c->fs_hz, wr = m->wr;
  const double w1 = mech_wn1(m), w2 = mech_wn2(m);
  /* p(1/2) = (p0 + p1)/2 + T (v0 - v1)/8,  p'(1/2) = 3 (p1 - p0) / (2T) - (v0 + v1)/4 */
  const double ym = 0.5 * (z0[0] + z1[0]) + 0.125 * T * wr * (z0[1] - z1[1]);
  const double vym = 1.5 * (z1[0] - z0[0]) / T - 0.25 * wr * (z0[1] + z1[1]);
  const double xm = 0.5 * (z0[2] + z1[2]) + 0.125 * T * wr * (z0[3] - z1[3]);
  *fy = *fx = 0.0;
  if (c->k3_drive_per_m2 != 0.0)
    *fy -= w1 * w1 * cubic(c->k3_drive_per_m2, ym, MECH_OUT_DUFFING_DRIVE, &m->duffing_out);
  if (c->k3_sense_per_m2 != 0.0)
    *fx -= w2 * w2 * cubic(c->k3_sense_per_m2, xm, MECH_OUT_DUFFING_SENSE, &m->duffing_out);
  if (c->nl_damp_drive_per_m2 != 0.0) /* (wn1/Q1) c y^2 y' (mech.h) */
    *fy -= w1 / m->q_now[0] * c->nl_damp_drive_per_m2 * ym * ym * vym;
  if (m->drift_kq_per_s2 != 0.0 || m->drift_dq_per_s != 0.0) {
    const double s = w1 / wn_at(c, c->f1_hz, c->temp_ref_k); /* as build_generator */
    *fx -= m->drift_kq_per_s2 * s * s * ym + m->drift_dq_per_s * s * vym;
  }
  if (m->elec_on) /* the electrodes' stiffness beyond the generator's (mech.h) */
    *fx -= (m->elec_kyx_per_s2 - m->elec_disc[0]) * ym -
           (m->elec_ke_per_s2 - m->elec_disc[1]) * xm;
}

void mech_step(mech_t *m, double f_drive_mps2, double f_sense_mps2, double rate_rad_s,
               double rate_dot_rad_s2)
{
  const double wr = m->wr;
  const double w = rate_rad_s / wr;
  const double a = m->cfg.full_kinematics ? rate_dot_rad_s2 / (wr * wr) : 0.0;
  if (!m->q_valid) build_q(m);
  if (!m->k_valid || w != m->coef[0] || a != m->coef[1]) build_k(m, w, a);

  const double in_scale = 1.0 / (wr * wr);
  double v[NA];
  v[0] = m->z[0];
  v[1] = m->z[1];
  v[2] = m->z[2];
  v[3] = m->z[3];
  v[4] = f_drive_mps2 * in_scale;
  v[5] = f_sense_mps2 * in_scale;
  if (m->cfg.brownian) {
    v[4] += m->noise_sd[0] * gauss_zig(&m->rng[0]);
    v[5] += m->noise_sd[1] * gauss_zig(&m->rng[1]);
  }
  for (int r = 0; r < MECH_NS; r++) {
    const double *kr = m->k[r];
    m->z[r] = kr[0] * v[0] + kr[1] * v[1] + kr[2] * v[2] + kr[3] * v[3] + kr[4] * v[4] +
              kr[5] * v[5];
  }
  if (m->elec_on) {
    m->elec_sum[0] += m->elec_kyx_per_s2;
    m->elec_sum[1] += m->elec_ke_per_s2;
    m->elec_n++;
  }
  if (m->held) {
    /* the held forces from the sample's motion without them, then their share of the
     * step (the step is linear in the inputs: Gamma's columns) */
    double fy, fx;
    held_forces(m, v, m->z, &fy, &fx);
    for (int r = 0; r < MECH_NS; r++)
      m->z[r] += m->k[r][4] * (fy * in_scale) + m->k[r][5] * (fx * in_scale);
  }
}

mech_state_t mech_state(const mech_t *m)
{
  mech_state_t s;
  s.y_m = m->z[0];
  s.vy_mps = m->z[1] * m->wr;
  s.x_m = m->z[2];
  s.vx_mps = m->z[3] * m->wr;
  return s;
}

void mech_set_state(mech_t *m, const mech_state_t *s)
{
  m->z[0] = s->y_m;
  m->z[1] = s->vy_mps / m->wr;
  m->z[2] = s->x_m;
  m->z[3] = s->vx_mps / m->wr;
}

double mech_wn1(const mech_t *m) { return m->clock * wn_at(&m->cfg, m->cfg.f1_hz, m->temp_k); }
double mech_wn2(const mech_t *m) { return m->clock * wn_at(&m->cfg, m->cfg.f2_hz, m->temp_k); }

double mech_q1(const mech_t *m) { return m->q_now[0]; }
double mech_q2(const mech_t *m) { return m->q_now[1]; }

/* Whether any held force of mech.h is on. */
static void update_held(mech_t *m)
{
  m->held = m->cfg.k3_drive_per_m2 != 0.0 || m->cfg.k3_sense_per_m2 != 0.0 ||
            m->cfg.nl_damp_drive_per_m2 != 0.0 || m->drift_kq_per_s2 != 0.0 ||
            m->drift_dq_per_s != 0.0 || m->elec_on;
}

int mech_set_coupling_drift(mech_t *m, double dkq_per_s2, double ddq_per_s)
{
  if (!(isfinite(dkq_per_s2) && isfinite(ddq_per_s))) return -1;
  m->drift_kq_per_s2 = dkq_per_s2;
  m->drift_dq_per_s = ddq_per_s;
  update_held(m);
  return 0;
}

int mech_set_elec(mech_t *m, double kyx_per_s2, double ke_per_s2)
{
  if (!(isfinite(kyx_per_s2) && fabs(kyx_per_s2) <= 1e9 && isfinite(ke_per_s2) &&
        ke_per_s2 >= 0.0))
    return -1;
  /* pull-in margin of mech_cfg_check, on the sum with the configured softening */
  const double w2 = 2.0 * kPi * m->cfg.f2_hz, lim = 0.5 * w2 * w2 - m->cfg.ke2_per_s2;
  int held_at_edge = 0;
  if (ke_per_s2 > lim) {
    ke_per_s2 = lim;
    m->duffing_out |= MECH_OUT_PULL_IN;
    held_at_edge = 1;
  }
  m->elec_kyx_per_s2 = kyx_per_s2;
  m->elec_ke_per_s2 = ke_per_s2;
  if (!m->elec_on && (kyx_per_s2 != 0.0 || ke_per_s2 != 0.0)) {
    m->elec_on = 1;
    update_held(m);
  }
  return held_at_edge;
}

int mech_elec_rebase(mech_t *m)
{
  if (m->elec_n == 0) return 0;
  const double kyx = m->elec_sum[0] / (double)m->elec_n, ke = m->elec_sum[1] / (double)m->elec_n;
  m->elec_sum[0] = m->elec_sum[1] = 0.0;
  m->elec_n = 0;
  const double w1 = mech_wn1(m), w2 = mech_wn2(m);
  const double kyx_step = 2.0 * w1 * m->cfg.refresh_eps * MECH_ELEC_KYX_REFRESH_DPS *
                          (kPi / 180.0);
  const double ke_step = 2.0 * m->cfg.refresh_eps * w2 * w2;
  if (fabs(kyx - m->elec_disc[0]) <= kyx_step && fabs(ke - m->elec_disc[1]) <= ke_step)
    return 0;
  const double old[2] = {m->elec_disc[0], m->elec_disc[1]};
  m->elec_disc[0] = kyx;
  m->elec_disc[1] = ke;
  if (discretise(m, m->temp_k) != 0) { /* not expected: the blocks stay as they were */
    m->elec_disc[0] = old[0];
    m->elec_disc[1] = old[1];
    return -2;
  }
  return 1;
}

double mech_kyx_total(const mech_t *m)
{
  const double s = mech_wn1(m) / wn_at(&m->cfg, m->cfg.f1_hz, m->cfg.temp_ref_k);
  return (m->cfg.kq_per_s2 + m->drift_kq_per_s2) * s * s + m->elec_kyx_per_s2;
}

double mech_wn2_eff(const mech_t *m)
{
  const double w2 = mech_wn2(m);
  return sqrt(w2 * w2 - m->cfg.ke2_per_s2 - m->elec_ke_per_s2);
}

unsigned mech_laws_out(mech_t *m)
{
  const unsigned f = m->q_out | m->duffing_out;
  m->duffing_out = 0u;
  return f;
}

double mech_noise_psd(const mech_t *m, int resonance)
{
  const double wn = resonance == 1 ? mech_wn1(m) : mech_wn2(m);
  const double q = resonance == 1 ? m->q_now[0] : m->q_now[1];
  /* (4-20): force PSD 4 kB T D, D = m wn / Q; divided by m^2 */
  return 4.0 * MECH_KB_J_PER_K * m->temp_k * wn / (q * m->cfg.mass_kg);
}
