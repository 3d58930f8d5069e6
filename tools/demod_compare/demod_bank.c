#include "demod_bank.h"

#include <stddef.h>

#include "dsp/butter.h"

const char *demod_name(demod_kind_t kind)
{
  static const char *const names[DK_COUNT] = {"lmsd", "rlsd", "kfd", "mult"};
  return (kind < DK_COUNT) ? names[kind] : "?";
}

int demod_setup(demod_t *d, demod_kind_t kind, double param, double fs_hz)
{
  d->kind = kind;
  d->param = param;
  switch (kind) {
  case DK_LMSD: return lmsd_init(&d->u.lmsd, &(lmsd_cfg_t){.mu = (float)param});
  case DK_RLSD: return rlsd_init(&d->u.rlsd, &(rlsd_cfg_t){.lambda = (float)param, .p0 = 1.0f});
  case DK_KFD:
    return kfd_init(&d->u.kfd,
                    &(kfd_cfg_t){.q = (float)DEMOD_KFD_Q, .r = (float)param, .p0 = 1.0f});
  case DK_MULT: {
    if (param == 0.0) {
      return multdemod_init(&d->u.mult, &(multdemod_cfg_t){NULL, 0u});
    }
    biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
    const int n = butter_design(BUTTER_LOWPASS, DEMOD_MULT_LP_ORDER, param, 0.0, fs_hz, sec,
                                BIQUAD_MAX_SECTIONS);
    if (n <= 0) {
      return -1;
    }
    return multdemod_init(&d->u.mult, &(multdemod_cfg_t){sec, (uint32_t)n});
  }
  case DK_COUNT:
  default: return -1;
  }
}
