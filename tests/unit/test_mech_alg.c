/* The mechanics' Taylor blocks (host_sim/plant/mech, exponential taken directly in the
 * truncated polynomial algebra) against the route it replaces: Eigen's exponential of
 * the 72 x 72 left-regular representation of the same algebra element, whose first
 * block column holds the blocks.
 *
 * The reference generator is written here from (2-20), (2-22) and (2-32) as a function
 * A(w, a, e) of the scaled rate w = Omega/wr, rate derivative a = alpha/wr^2 and
 * frequency deviation e, in mech.h's coordinates z = [y, y'/wr, x, x'/wr], inputs
 * f/wr^2, time in units of 1/wr; its coefficient per monomial is extracted by finite
 * differences (exact for the polynomial) and checked by re-evaluating A at an
 * arbitrary point. The monomial order is the one mech.h documents. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>

#include "plant/mech.h"
#include "matexp_ref.h"

enum { NS = 4, NA = 6, NM = 12, NBIG = NM * NA };

static const double kPi = 3.14159265358979323846;

/* mech.h: {1, e, e^2, w, w e, w e^2, w^2, w^2 e, w^3, a, w a, a e}; exponents (w, a, e) */
static const int kMonoRef[NM][3] = {{0, 0, 0}, {0, 0, 1}, {0, 0, 2}, {1, 0, 0},
                                    {1, 0, 1}, {1, 0, 2}, {2, 0, 0}, {2, 0, 1},
                                    {3, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 1, 1}};

static int mono_of(int pw, int pa, int pe)
{
  for (int i = 0; i < NM; i++)
    if (kMonoRef[i][0] == pw && kMonoRef[i][1] == pa && kMonoRef[i][2] == pe) return i;
  return -1;
}

/* h A(w, a, e) augmented [A B; 0 0], at structure temperature tk, h = wr / fs. */
static void gen_at(const mech_cfg_t *c, double tk, double w, double a, double e, double g[NA][NA])
{
  const double wr = 2.0 * kPi * c->f1_hz;
  const double s = (1.0 - 0.5 * c->ket_per_k * (tk - c->temp_ref_k)) * (1.0 + e); /* (2-32) */
  const double r1 = 2.0 * kPi * c->f1_hz * s / wr, r2 = 2.0 * kPi * c->f2_hz * s / wr;
  const double kq = c->kq_per_s2 * s * s / (wr * wr), dq = c->dq_per_s * s / wr;
  const double fk = c->full_kinematics ? 1.0 : 0.0;
  const double h = wr / c->fs_hz;
  memset(g, 0, sizeof(double) * NA * NA);
  /* y'' = -wn1^2 y - wn1/Q1 y' + u1  [- 2 Omega x' - alpha x + Omega^2 y] */
  g[0][1] = 1.0;
  g[1][0] = -r1 * r1 + fk * w * w;
  g[1][1] = -r1 / c->q1;
  g[1][2] = -fk * a;
  g[1][3] = -fk * 2.0 * w;
  g[1][4] = 1.0;
  /* x'' = -wn2^2 x - wn2/Q2 x' + 2 Omega y' - kq y - dq y' + u2  [+ alpha y + Omega^2 x] */
  g[2][3] = 1.0;
  g[3][0] = -kq + fk * a;
  g[3][1] = 2.0 * w - dq;
  g[3][2] = -r2 * r2 + fk * w * w;
  g[3][3] = -r2 / c->q2;
  g[3][5] = 1.0;
  for (int i = 0; i < NA; i++)
    for (int j = 0; j < NA; j++) g[i][j] *= h;
}

/* Coefficients of the polynomial A(w, a, e) per monomial (degree <= 2 in w and e,
 * 1 in a, no products; verified below). */
static void gen_coeffs(const mech_cfg_t *c, double tk, double cf[NM][NA][NA])
{
  double g0[NA][NA], gp[NA][NA], gm[NA][NA];
  memset(cf, 0, sizeof(double) * NM * NA * NA);
  gen_at(c, tk, 0, 0, 0, g0);
  memcpy(cf[mono_of(0, 0, 0)], g0, sizeof g0);
  for (int v = 0; v < 2; v++) { /* e, then w */
    gen_at(c, tk, v ? 1.0 : 0.0, 0.0, v ? 0.0 : 1.0, gp);
    gen_at(c, tk, v ? -1.0 : 0.0, 0.0, v ? 0.0 : -1.0, gm);
    const int i1 = v ? mono_of(1, 0, 0) : mono_of(0, 0, 1);
    const int i2 = v ? mono_of(2, 0, 0) : mono_of(0, 0, 2);
    for (int r = 0; r < NA; r++)
      for (int q = 0; q < NA; q++) {
        cf[i1][r][q] = 0.5 * (gp[r][q] - gm[r][q]);
        cf[i2][r][q] = 0.5 * (gp[r][q] + gm[r][q]) - g0[r][q];
      }
  }
  gen_at(c, tk, 0.0, 1.0, 0.0, gp);
  for (int r = 0; r < NA; r++)
    for (int q = 0; q < NA; q++) cf[mono_of(0, 1, 0)][r][q] = gp[r][q] - g0[r][q];
  /* the coefficients reproduce A at an arbitrary point */
  const double w = 0.37, a = -0.61, e = 0.23;
  gen_at(c, tk, w, a, e, gp);
  for (int r = 0; r < NA; r++)
    for (int q = 0; q < NA; q++) {
      double s = 0.0;
      for (int i = 0; i < NM; i++)
        s += cf[i][r][q] * pow(w, kMonoRef[i][0]) * pow(a, kMonoRef[i][1]) *
             pow(e, kMonoRef[i][2]);
      assert_true(fabs(s - gp[r][q]) <= 1e-14 * (1.0 + fabs(gp[r][q])));
    }
}

/* Worst relative difference (per block, against the block's largest entry) between
 * mech's blocks and the first block column of exp(L), L the left-regular
 * representation. Also the worst absolute difference against the largest entry of all
 * blocks (out). */
static double compare_with_rep(const mech_t *m, const mech_cfg_t *c, double tk, double *glob)
{
  static double cf[NM][NA][NA];
  static double big[NBIG * NBIG], ebig[NBIG * NBIG];
  gen_coeffs(c, tk, cf);
  memset(big, 0, sizeof big);
  for (int g = 0; g < NM; g++)
    for (int j = 0; j < NM; j++) {
      const int i = mono_of(kMonoRef[g][0] + kMonoRef[j][0], kMonoRef[g][1] + kMonoRef[j][1],
                            kMonoRef[g][2] + kMonoRef[j][2]);
      if (i < 0) continue; /* outside the truncation */
      for (int r = 0; r < NA; r++)
        for (int q = 0; q < NA; q++) big[(i * NA + r) * NBIG + j * NA + q] += cf[g][r][q];
    }
  assert_int_equal(ref_matexp(NBIG, big, ebig), 0);
  double worst = 0.0, dmax = 0.0, amax = 0.0;
  for (int i = 0; i < NM; i++) {
    double d = 0.0, mx = 0.0;
    for (int r = 0; r < NS; r++)
      for (int q = 0; q < NA; q++) {
        const double ref = ebig[(i * NA + r) * NBIG + q];
        d = fmax(d, fabs(m->blk[i][r][q] - ref));
        mx = fmax(mx, fabs(ref));
      }
    dmax = fmax(dmax, d);
    amax = fmax(amax, mx);
    if (mx > 0.0) worst = fmax(worst, d / mx);
    else worst = fmax(worst, d); /* an exactly zero block must come out zero */
  }
  *glob = dmax / amax;
  return worst;
}

static void check_case(const char *name, const mech_cfg_t *c, double t_init_k, double t_hot_k)
{
  static mech_t m;
  assert_int_equal(mech_init(&m, c, t_init_k, 1u), 0);
  double tk = t_init_k;
  if (t_hot_k != t_init_k) {
    assert_int_equal(mech_set_temp(&m, t_hot_k), 0);
    assert_true(m.refresh_count == 1); /* the blocks were recomputed at t_hot_k */
    assert_true(m.eps == 0.0);
    tk = t_hot_k;
  }
  double glob = 0.0;
  const double worst = compare_with_rep(&m, c, tk, &glob);
  printf("%-34s: per-block rel diff %.2e, against the largest block %.2e\n", name, worst, glob);
  assert_true(worst < 1e-13);
  assert_true(glob < 1e-14);
}

static void test_default(void **state)
{
  (void)state;
  mech_cfg_t c;
  mech_default_cfg(&c);
  check_case("default, T0", &c, c.temp_ref_k, c.temp_ref_k);
  c.full_kinematics = 0;
  check_case("default, (2-22) only", &c, c.temp_ref_k, c.temp_ref_k);
}

static void test_high_q_coupled(void **state)
{
  (void)state;
  mech_cfg_t c;
  mech_default_cfg(&c);
  c.q1 = 600.0;
  c.q2 = 600.0;
  c.f2_hz = 1510.0;
  c.kq_per_s2 = 2.0 * (2.0 * kPi * c.f1_hz) * 1500.0 * kPi / 180.0; /* 1500 deg/s quadrature */
  c.dq_per_s = 2.0 * 3.0 * kPi / 180.0;
  check_case("Q 600, quadrature and damping", &c, 310.0, 310.0);
}

static void test_hot_refresh(void **state)
{
  (void)state;
  mech_cfg_t c;
  mech_default_cfg(&c);
  c.kq_per_s2 = 5e4;
  /* +80 K: e = -1.6e-3 past refresh_eps, the blocks are recomputed there */
  check_case("hot refresh, T0 + 80 K", &c, c.temp_ref_k, c.temp_ref_k + 80.0);
}

static void test_low_rate_many_squarings(void **state)
{
  (void)state;
  mech_cfg_t c;
  mech_default_cfg(&c);
  c.fs_hz = 4500.0; /* wn T ~ 2.8: large argument, several squarings */
  check_case("fs 4.5 kHz", &c, c.temp_ref_k - 30.0, c.temp_ref_k - 30.0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_default),
      cmocka_unit_test(test_high_q_coupled),
      cmocka_unit_test(test_hot_refresh),
      cmocka_unit_test(test_low_rate_many_squarings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
