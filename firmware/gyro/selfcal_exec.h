/* Self-calibration, sample-rate half: executes one measurement job per request while
 * the supervisor is in SWEEP. Per tick it only steps the excitation frequency, watches
 * the amplitude against the ADC budget and accumulates sums; everything that needs
 * division, trigonometry or double precision is done by the background sequencer
 * (selfcal.h) from the results.
 *
 * Excitation: force command f_cmd (Ks*V^2) at force phase P, at the NCO frequency set
 * by the half-rate phase step (f = 2 half_step fs / 2^32, nco.h); the synthesis is the
 * drive's own (drive_synth.h), so the measurement includes every part of the signal
 * chain the loops will see.
 *
 * Measured quantity: the drive LMSD phasor Z = w_i + j w_q, from its weights (gyro.h convention).
 * A job with sense 1 identifies the sense mode instead (selfcal.h): the excitation goes
 * to the feedback electrodes (their own synthesis, sense.fb_scheme), Z is the sense
 * LMSD's phasor, and the drive electrodes rest at 0 V (gyro.c: gyro_tick_sweep).
 * Every job holds the tuning electrodes at the DC code tune_code, a RINGDOWN's decay at
 * tune_ring_code (the tuning slope: the free frequency with and without a tuning
 * voltage, selfcal.c); the interrupt writes it on the sweep's idle ticks.
 *
 * Jobs:
 *   CHIRP     half_step[0] + k chirp_delta for chirp_ticks ticks; records the largest
 *             |Z| and the half-step at which it occurred. Over-amplitude aborts the
 *             job (aborted = 1) and stops the excitation.
 *   RINGDOWN  excite at half_step[0] until |Z| >= amp_target_v, or |Z| grew by less
 *             than 1 % in the last 512 ticks, or settle_ticks passed; then f_cmd = 0 and,
 *             from the next tick, the free oscillation is followed until |Z| < |Z0| / e or for avg_ticks,
 *             whichever comes first: rd_ticks is the length of the decay followed,
 *             rd_amp2_end_v2 the |Z|^2 it ended at (the time constant tau = 2Q/wn of
 *             (6-12) from the log-amplitude slope), rd_phase_rad the unwrapped
 *             rotation of Z over it (the free frequency minus the NCO frequency).
 *   STEPS     for each point: settle (settle_ticks for the first, step_settle_ticks for
 *             the others), then average Z over avg_ticks. Over-amplitude halves f_cmd
 *             and restarts the point's settling (start low, back off); on a point
 *             unexcited (off_mask) it is only counted (backoffs): no force to lower.
 *   HOLD      excite at half_step[0] with (f_cmd, P) for avg_ticks, then report done
 *             and keep exciting (the drive loops take over from this state).
 *   QUIET     f_cmd = 0 for avg_ticks (let a previous vibration ring down).
 * After a job completes the last excitation is held until the next job.
 *
 * Hand-off: the background writes job, then job_seq + 1 (one writer); the ISR takes it
 * at a tick it calls selfcal_exec_take on, runs it, fills res and then stores done_seq = job_seq.
 * The background reads res only when done_seq == job_seq (signal fences order the stores, the same
 * scheme as params.h).
 */
#ifndef SELFCAL_EXEC_H
#define SELFCAL_EXEC_H

#include <stdatomic.h>
#include <stdint.h>

#define SELFCAL_MAX_PTS 9u

typedef enum {
  SELFCAL_JOB_NONE = 0u,
  SELFCAL_JOB_CHIRP = 1u,
  SELFCAL_JOB_RINGDOWN = 2u,
  SELFCAL_JOB_STEPS = 3u,
  SELFCAL_JOB_HOLD = 4u,
  SELFCAL_JOB_QUIET = 5u
} selfcal_job_kind_t;

typedef struct {
  uint32_t kind;                       /* selfcal_job_kind_t */
  uint32_t n_pts;                      /* STEPS: 1..SELFCAL_MAX_PTS */
  uint32_t half_step[SELFCAL_MAX_PTS]; /* STEPS: each point; others: [0] */
  int32_t chirp_delta;                 /* CHIRP: half-step change per tick */
  uint32_t chirp_ticks;
  uint32_t settle_ticks, step_settle_ticks;
  uint32_t avg_ticks;
  float f_cmd_v2;
  float p_rad;
  float amp_max_v;    /* back-off threshold (ADC budget) */
  float amp_target_v; /* RINGDOWN: stop exciting above */
  uint32_t sense;     /* 1: the sense channel (feedback electrodes, sense LMSD) */
  uint32_t off_mask;  /* STEPS: bit i set, point i unexcited (f_cmd 0) */
  uint16_t tune_code, tune_ring_code; /* tuning electrodes' DAC code; in a decay */
} selfcal_job_t;

typedef struct {
  float z_re[SELFCAL_MAX_PTS], z_im[SELFCAL_MAX_PTS]; /* STEPS: mean Z per point */
  float f_cmd_v2[SELFCAL_MAX_PTS];                    /* STEPS: excitation it had */
  float peak_amp_v;                                   /* CHIRP */
  uint32_t peak_half_step;                            /* CHIRP */
  float rd_amp2_0_v2;   /* RINGDOWN: |Z|^2 when the excitation stopped */
  float rd_f_cmd_v2;    /* RINGDOWN: the excitation it had */
  uint32_t rd_ticks;    /* RINGDOWN: length of the decay followed, ticks */
  float rd_amp2_end_v2; /* RINGDOWN: |Z|^2 at its end */
  float rd_phase_rad;   /* RINGDOWN: rotation of Z over rd_ticks */
  uint32_t aborted;     /* CHIRP: over-amplitude */
  uint32_t backoffs;    /* halvings of f_cmd */
  uint32_t ticks;       /* length of the job */
} selfcal_result_t;

typedef struct {
  selfcal_job_t job;         /* background writes before publishing job_seq */
  selfcal_result_t res;      /* ISR writes before publishing done_seq */
  _Atomic uint32_t job_seq;  /* background writes */
  _Atomic uint32_t done_seq; /* ISR writes */
  /* ISR state */
  uint32_t running_seq;
  uint32_t active; /* a job is being executed */
  uint32_t stage;  /* job-specific sub-state */
  uint32_t idx, ticks, check_ticks;
  uint32_t half_step;
  float f_cmd_v2, p_rad;
  float amp_max2, amp_ref2;
  float blk_re, blk_im, acc_re, acc_im;
  uint32_t blk_n;
  float z_prev_re, z_prev_im, phase_acc;
  float f_on_v2;      /* STEPS: the excited points' force (halved by a back-off) */
  uint32_t sense;     /* the running job's channel (gyro.c reads it every tick) */
  uint16_t tune_code; /* the tuning electrodes' code now (the sweep's idle ticks) */
} selfcal_exec_t;

/* ISR: entering SWEEP. Drops any running job, excitation off, at half_step. */
void selfcal_exec_reset(selfcal_exec_t *x, uint32_t half_step);

/* ISR: take a newly posted job, if any, and start it. Called on some ticks only (the
 * caller's lighter ones): a job waits for it at most a few ticks. */
void selfcal_exec_take(selfcal_exec_t *x);

/* ISR: one tick in SWEEP with this tick's drive LMSD weights. The excitation of this
 * tick and the NCO half-step of the next are then x->f_cmd_v2, x->p_rad, x->half_step
 * (read in place: no outputs through memory on the tick). */
void selfcal_exec_tick(selfcal_exec_t *x, float w_i, float w_q);

/* Background: publish a job. Returns 0, or -1 (nothing posted) when the previous job
 * has not completed or the job is malformed. */
int selfcal_exec_post(selfcal_exec_t *x, const selfcal_job_t *job);

/* Background: 1 and the result copied to *out when the posted job has completed. */
int selfcal_exec_poll(selfcal_exec_t *x, selfcal_result_t *out);

#endif /* SELFCAL_EXEC_H */
