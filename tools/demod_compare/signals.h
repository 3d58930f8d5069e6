/* Inputs of the comparison protocol (thesis 5.4.3): demodulation references from the
 * firmware NCO, and seeded white Gaussian noise. */
#ifndef DEMOD_SIGNALS_H
#define DEMOD_SIGNALS_H

#include <stddef.h>
#include <stdint.h>

#include "plant/rng.h"

/* The simulator's seeded generator (host_sim/plant/rng.h: xoshiro256**, polar normals). */
typedef rng_t noise_rng_t;

void noise_seed(noise_rng_t *g, uint64_t seed);

/* n samples of N(0, sigma^2), rounded to float. */
void noise_fill(noise_rng_t *g, float *out, size_t n, double sigma);

/* sin(wc k), cos(wc k), k = 0..n-1, from dsp/nco.h started at phase 0: the references
 * exactly as the firmware produces them. Returns 0, or -1 for an invalid frequency. */
int refs_fill(float *ref_sin, float *ref_cos, size_t n, double fc_hz, double fs_hz);

#endif /* DEMOD_SIGNALS_H */
