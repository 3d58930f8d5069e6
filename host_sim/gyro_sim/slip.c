/* See slip.h. */
#include "slip.h"

#include <math.h>
#include <string.h>

#include "plant/plant_const.h"

void slip_init(slip_t *s, double dt_s)
{
  memset(s, 0, sizeof *s);
  s->k_avg = 1.0 - exp(-dt_s / SLIP_AVG_S);
}

void slip_sample(slip_t *s, int running, int locked, double phase_rad, double force)
{
  if (!running) {
    s->armed = 0;
    return;
  }
  if (!s->armed) {
    if (!locked) return;
    s->armed = 1;
    s->re = force * cos(phase_rad);
    s->im = force * sin(phase_rad);
    s->prev = s->unwrapped = s->ref = phase_rad;
    return;
  }
  s->re += s->k_avg * (force * cos(phase_rad) - s->re);
  s->im += s->k_avg * (force * sin(phase_rad) - s->im);
  if (s->re == 0.0 && s->im == 0.0) return; /* never a force since lock: no phase */
  const double p = atan2(s->im, s->re);
  s->unwrapped += remainder(p - s->prev, PLANT_TWO_PI);
  s->prev = p;
  if (fabs(s->unwrapped - s->ref) > 0.5 * PLANT_PI) {
    s->count++;
    s->ref = s->unwrapped;
  }
}
