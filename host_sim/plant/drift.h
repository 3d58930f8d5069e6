/* Slow random drift of a plant coefficient: a first-order Gauss-Markov process (host
 * plant, double precision). The plant drives the quadrature coupling k_q and the
 * damping coupling d_q of the mechanics (mech.h) with one each.
 *
 * Physics: the anisoelastic and anisodamping couplings of a vibratory gyro follow the
 * die's stress and the package's gas, which relax and wander slowly after assembly and
 * with humidity and aging; the resulting bias wander is correlated over a time
 * constant, the exponentially correlated ("Markov") noise of IEEE Std 952-1997, annex C
 * (Allan variance of correlated noise), modelled as a first-order Gauss-Markov process
 * in inertial-sensor error models (El-Sheimy, Hou & Niu, "Analysis and modeling of
 * inertial sensors using Allan variance", IEEE Trans. Instrum. Meas. 57 (2008) 140):
 *     dx/dt = -x / tau + w(t),   stationary rms sigma, autocorrelation sigma^2 e^(-|t|/tau),
 * i.e. white noise through a first-order low-pass: one-sided PSD 4 sigma^2 tau /
 * (1 + (2 pi f tau)^2), a random walk for t << tau and bounded at sigma for t >> tau
 * (a pure random walk would grow without bound). Exact discretisation over the update
 * period dt: x(k+1) = phi x(k) + sigma sqrt(1 - phi^2) n(k), phi = exp(-dt/tau),
 * n ~ N(0,1).
 * The process starts at 0: the coefficient has its configured (calibrated) value at
 * power-on and drifts from there, its variance sigma^2 (1 - exp(-2t/tau)).
 * sigma = 0: x stays 0 and nothing is drawn. */
#ifndef PLANT_DRIFT_H
#define PLANT_DRIFT_H

#include <stdint.h>

#include "plant/rng.h"

typedef struct {
  double sigma, tau_s, dt_s;
} drift_cfg_t;

typedef struct {
  int active;
  double phi, kick; /* exp(-dt/tau), sigma sqrt(1 - phi^2) */
  double x;
  rng_t rng;
} drift_t;

/* 0 if sigma >= 0, tau > 0, dt > 0, all finite. */
int drift_check(const drift_cfg_t *cfg);

/* Validates and seeds (rng_seed(seed, stream)). Returns 0, or -1 with d unchanged. */
int drift_init(drift_t *d, const drift_cfg_t *cfg, uint64_t seed, uint64_t stream);

/* Advance one update period; returns the new value. */
double drift_step(drift_t *d);

#endif /* PLANT_DRIFT_H */
