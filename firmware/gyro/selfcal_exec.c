#include "gyro/selfcal_exec.h"

#include <stddef.h>
#include <string.h>

#include "dsp/fastmath.h"
#include "dsp/ramfunc.h"
#include "hal/hal_dac.h" /* HAL_DAC_CODE_MID: 0 V on the tuning electrodes */

/* Sums of Z are formed in blocks of this many ticks, then the block sums are added:
 * a single float sum over 10^4..10^5 ticks would lose ~1e-4 of its value. */
#define SC_BLOCK 256u
/* e^-2: |Z|^2 after one time constant of free decay. */
#define SC_INV_E2 0.1353352832f
/* Ring-down: unwrap the phase of Z every this many ticks (|df| < fs/128 = 390 Hz). */
#define SC_PHASE_EVERY 64u
/* Ring-down excitation: growth check period and the 1 % amplitude growth threshold. */
#define SC_GROWTH_EVERY 512u
#define SC_GROWTH2 1.0201f

enum { ST_SETTLE = 0u, ST_AVG = 1u, ST_EXCITE = 2u, ST_STOP = 3u, ST_RING = 4u, ST_DONE = 5u };

void selfcal_exec_reset(selfcal_exec_t *x, uint32_t half_step)
{
  x->running_seq = atomic_load_explicit(&x->job_seq, memory_order_relaxed);
  atomic_store_explicit(&x->done_seq, x->running_seq, memory_order_relaxed);
  x->active = 0u;
  x->stage = ST_DONE;
  x->idx = x->ticks = x->check_ticks = 0u;
  x->half_step = half_step;
  x->f_cmd_v2 = 0.0f;
  x->p_rad = 0.0f;
  x->amp_max2 = x->amp_ref2 = 0.0f;
  x->blk_re = x->blk_im = x->acc_re = x->acc_im = 0.0f;
  x->blk_n = 0u;
  x->z_prev_re = x->z_prev_im = x->phase_acc = 0.0f;
  x->f_on_v2 = 0.0f;
  x->sense = 0u;
  x->tune_code = (uint16_t)HAL_DAC_CODE_MID;
}

GYRO_RAMFUNC static void begin_point(selfcal_exec_t *x)
{
  x->stage = ST_SETTLE;
  x->check_ticks = 0u;
  x->half_step = x->job.half_step[x->idx];
  x->f_cmd_v2 = ((x->job.off_mask >> x->idx) & 1u) != 0u ? 0.0f : x->f_on_v2;
  x->blk_re = x->blk_im = x->acc_re = x->acc_im = 0.0f;
  x->blk_n = 0u;
}

GYRO_RAMFUNC static void start_job(selfcal_exec_t *x)
{
  const selfcal_job_t *j = &x->job;
  /* res was cleared by selfcal_exec_post, in the background: not on the tick. */
  x->active = 1u;
  x->idx = 0u;
  x->ticks = 0u;
  x->check_ticks = 0u;
  x->amp_max2 = j->amp_max_v * j->amp_max_v;
  x->amp_ref2 = 0.0f;
  x->f_cmd_v2 = j->f_cmd_v2;
  x->f_on_v2 = j->f_cmd_v2;
  x->p_rad = j->p_rad;
  x->sense = j->sense;
  x->tune_code = j->tune_code;
  x->half_step = j->half_step[0];
  x->stage = ST_SETTLE;
  if (j->kind == SELFCAL_JOB_STEPS) {
    begin_point(x);
  } else if (j->kind == SELFCAL_JOB_RINGDOWN) {
    x->stage = ST_EXCITE;
  } else if (j->kind == SELFCAL_JOB_QUIET) {
    x->f_cmd_v2 = 0.0f;
  }
}

GYRO_RAMFUNC static void finish(selfcal_exec_t *x)
{
  x->res.ticks = x->ticks;
  x->active = 0u;
  x->stage = ST_DONE;
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&x->done_seq, x->running_seq, memory_order_relaxed);
}

GYRO_RAMFUNC static void tick_steps(selfcal_exec_t *x, float w_i, float w_q, float amp2)
{
  const selfcal_job_t *j = &x->job;
  if (amp2 > x->amp_max2) {
    /* Over the ADC budget: back off and let the point settle again; unexcited, there is
     * no force to lower (counted only: the background judges the point). */
    x->res.backoffs++;
    if (x->f_cmd_v2 > 0.0f) {
      x->f_on_v2 *= 0.5f;
      begin_point(x);
      return;
    }
  }
  x->check_ticks++;
  if (x->stage == ST_SETTLE) {
    const uint32_t need = x->idx == 0u ? j->settle_ticks : j->step_settle_ticks;
    if (x->check_ticks >= need) {
      x->stage = ST_AVG;
      x->check_ticks = 0u;
    }
    return;
  }
  x->blk_re += w_i;
  x->blk_im += w_q;
  if (++x->blk_n >= SC_BLOCK) {
    x->acc_re += x->blk_re;
    x->acc_im += x->blk_im;
    x->blk_re = x->blk_im = 0.0f;
    x->blk_n = 0u;
  }
  if (x->check_ticks >= j->avg_ticks) {
    const float inv_n = 1.0f / (float)j->avg_ticks;
    x->res.z_re[x->idx] = (x->acc_re + x->blk_re) * inv_n;
    x->res.z_im[x->idx] = (x->acc_im + x->blk_im) * inv_n;
    x->res.f_cmd_v2[x->idx] = x->f_cmd_v2;
    if (++x->idx >= j->n_pts) {
      x->idx = j->n_pts - 1u;
      finish(x);
    } else {
      begin_point(x);
    }
  }
}

GYRO_RAMFUNC static void tick_ringdown(selfcal_exec_t *x, float w_i, float w_q, float amp2)
{
  const selfcal_job_t *j = &x->job;
  x->check_ticks++;
  if (x->stage == ST_EXCITE) {
    if (amp2 > x->amp_max2) {
      x->f_cmd_v2 *= 0.5f;
      x->res.backoffs++;
    }
    int stop = amp2 >= j->amp_target_v * j->amp_target_v || x->check_ticks >= j->settle_ticks;
    if ((x->check_ticks % SC_GROWTH_EVERY) == 0u) {
      /* Growth stalled: the response has settled as far as it usefully will. */
      if (x->check_ticks > SC_GROWTH_EVERY && amp2 < SC_GROWTH2 * x->amp_ref2) stop = 1;
      x->amp_ref2 = amp2;
    }
    if (stop) {
      /* The excitation stops here and the decay's reference is taken on the next tick:
       * this tick already carries the excitation's checks (the interrupt's budget). */
      x->res.rd_f_cmd_v2 = x->f_cmd_v2;
      x->f_cmd_v2 = 0.0f;
      x->stage = ST_STOP;
    }
    return;
  }
  if (x->stage == ST_STOP) {
    x->res.rd_amp2_0_v2 = amp2;
    x->amp_ref2 = amp2;
    x->z_prev_re = w_i;
    x->z_prev_im = w_q;
    x->phase_acc = 0.0f;
    x->check_ticks = 0u;
    x->stage = ST_RING;
    x->tune_code = j->tune_ring_code; /* the decay's tuning voltage (the idle ticks) */
    return;
  }
  const int end = amp2 < SC_INV_E2 * x->amp_ref2 || x->check_ticks >= j->avg_ticks;
  if (end || (x->check_ticks % SC_PHASE_EVERY) == 0u) {
    /* Rotation since the last look: arg(Z conj(Z_prev)). */
    const float cr = w_q * x->z_prev_re - w_i * x->z_prev_im;
    const float dt = w_i * x->z_prev_re + w_q * x->z_prev_im;
    x->phase_acc += fm_atan2f(cr, dt);
    x->z_prev_re = w_i;
    x->z_prev_im = w_q;
  }
  if (end) {
    x->res.rd_ticks = x->check_ticks;
    x->res.rd_amp2_end_v2 = amp2;
    x->res.rd_phase_rad = x->phase_acc;
    finish(x);
  }
}

GYRO_RAMFUNC static void tick_chirp(selfcal_exec_t *x, float amp2)
{
  const selfcal_job_t *j = &x->job;
  if (amp2 > x->amp_max2) {
    x->res.aborted = 1u;
    x->f_cmd_v2 = 0.0f;
    finish(x);
    return;
  }
  if (amp2 > x->amp_ref2) {
    x->amp_ref2 = amp2;
    x->res.peak_half_step = x->half_step;
  }
  x->half_step += (uint32_t)j->chirp_delta; /* modular: a negative delta steps down */
  if (++x->check_ticks >= j->chirp_ticks) {
    x->res.peak_amp_v = fm_sqrtf(x->amp_ref2);
    finish(x);
  }
}

GYRO_RAMFUNC void selfcal_exec_take(selfcal_exec_t *x)
{
  const uint32_t seq = atomic_load_explicit(&x->job_seq, memory_order_relaxed);
  atomic_signal_fence(memory_order_acquire);
  if (seq != x->running_seq) {
    x->running_seq = seq;
    start_job(x);
  }
}

GYRO_RAMFUNC void selfcal_exec_tick(selfcal_exec_t *x, float w_i, float w_q)
{
  /* The measurement of this tick belongs to the excitation of the previous ones. */
  if (x->active != 0u) {
    x->ticks++;
    const float amp2 = w_i * w_i + w_q * w_q;
    switch ((selfcal_job_kind_t)x->job.kind) {
    case SELFCAL_JOB_STEPS: tick_steps(x, w_i, w_q, amp2); break;
    case SELFCAL_JOB_RINGDOWN: tick_ringdown(x, w_i, w_q, amp2); break;
    case SELFCAL_JOB_CHIRP: tick_chirp(x, amp2); break;
    case SELFCAL_JOB_HOLD:
    case SELFCAL_JOB_QUIET:
      if (++x->check_ticks >= x->job.avg_ticks) finish(x);
      break;
    case SELFCAL_JOB_NONE:
    default: finish(x); break;
    }
  }
}

static int job_ok(const selfcal_job_t *j)
{
  if (!(fm_isfinite(j->f_cmd_v2) && j->f_cmd_v2 >= 0.0f && fm_isfinite(j->p_rad) &&
        j->amp_max_v > 0.0f && fm_isfinite(j->amp_max_v))) {
    return 0;
  }
  switch ((selfcal_job_kind_t)j->kind) {
  case SELFCAL_JOB_STEPS:
    return j->n_pts >= 1u && j->n_pts <= SELFCAL_MAX_PTS && j->avg_ticks >= 1u;
  case SELFCAL_JOB_CHIRP: return j->chirp_ticks >= 1u;
  case SELFCAL_JOB_RINGDOWN:
    return j->avg_ticks >= 1u && j->settle_ticks >= 1u && j->amp_target_v > 0.0f &&
           j->amp_target_v < j->amp_max_v;
  case SELFCAL_JOB_HOLD:
  case SELFCAL_JOB_QUIET: return j->avg_ticks >= 1u;
  case SELFCAL_JOB_NONE:
  default: return 0;
  }
}

int selfcal_exec_post(selfcal_exec_t *x, const selfcal_job_t *job)
{
  if (x == NULL || job == NULL || !job_ok(job)) return -1;
  const uint32_t seq = atomic_load_explicit(&x->job_seq, memory_order_relaxed);
  if (atomic_load_explicit(&x->done_seq, memory_order_relaxed) != seq) return -1;
  /* Between jobs the background owns res (done_seq == job_seq): the new job's result
   * starts from zero here rather than on the interrupt's first tick of the job. */
  memset(&x->res, 0, sizeof x->res);
  x->job = *job;
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&x->job_seq, seq + 1u, memory_order_relaxed);
  return 0;
}

int selfcal_exec_poll(selfcal_exec_t *x, selfcal_result_t *out)
{
  if (x == NULL || out == NULL) return 0;
  const uint32_t seq = atomic_load_explicit(&x->job_seq, memory_order_relaxed);
  if (atomic_load_explicit(&x->done_seq, memory_order_relaxed) != seq) return 0;
  atomic_signal_fence(memory_order_acquire);
  *out = x->res;
  return 1;
}
