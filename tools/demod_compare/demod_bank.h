/* The four demodulators of thesis 5.4.3 behind one interface, each set by its single
 * bandwidth parameter, built from the firmware kernels (host tool only).
 *
 *   lmsd  param = mu                       (lmsd.h)
 *   rlsd  param = lambda, P(0) = I         (rlsd.h)
 *   kfd   param = R, Q = 0.0002 I, P(0) = I (kfd.h; only q/R sets the bandwidth)
 *   mult  param = cut-off in Hz of its own 2nd-order Butterworth low-pass (multdemod.h,
 *         butter.h); 0 = no own low-pass (the thesis's arrangement: the common 100 Hz
 *         output filter is its only low-pass)
 * The output is the in-phase estimate (coefficient of the sine reference).
 */
#ifndef DEMOD_BANK_H
#define DEMOD_BANK_H

#include "dsp/kfd.h"
#include "dsp/lmsd.h"
#include "dsp/multdemod.h"
#include "dsp/rlsd.h"

typedef enum { DK_LMSD = 0, DK_RLSD, DK_KFD, DK_MULT, DK_COUNT } demod_kind_t;

#define DEMOD_MULT_LP_ORDER 2u
#define DEMOD_KFD_Q 0.0002

typedef struct {
  demod_kind_t kind;
  double param;
  union {
    lmsd_t lmsd;
    rlsd_t rlsd;
    kfd_t kfd;
    multdemod_t mult;
  } u;
} demod_t;

/* "lmsd", "rlsd", "kfd", "mult" */
const char *demod_name(demod_kind_t kind);

/* Build a demodulator in its initial state. Returns 0, or -1 for a parameter the kernel
 * rejects (or a low-pass that cannot be designed). */
int demod_setup(demod_t *d, demod_kind_t kind, double param, double fs_hz);

/* One sample; returns the in-phase estimate. */
static inline float demod_step(demod_t *d, float x, float ref_sin, float ref_cos)
{
  switch (d->kind) {
  case DK_LMSD: lmsd_step(&d->u.lmsd, x, ref_sin, ref_cos); return lmsd_in_phase(&d->u.lmsd);
  case DK_RLSD: rlsd_step(&d->u.rlsd, x, ref_sin, ref_cos); return rlsd_in_phase(&d->u.rlsd);
  case DK_KFD: kfd_step(&d->u.kfd, x, ref_sin, ref_cos); return kfd_in_phase(&d->u.kfd);
  case DK_MULT:
  case DK_COUNT:
  default:
    multdemod_step(&d->u.mult, x, ref_sin, ref_cos);
    return multdemod_in_phase(&d->u.mult);
  }
}

#endif /* DEMOD_BANK_H */
