/* Self-calibration sequencer (background loop): identifies the drive resonance through the
 * firmware's own signal chain and prepares the hand-over to the drive loops.
 *
 * The thesis (7.2.2) sweeps in 2 Hz steps; at Q = 600 one step would need seconds to
 * settle and the 2-3 Hz bandwidth would fall between two steps. Instead:
 *   1. QUIET, CHIRP up f_lo -> f_hi, QUIET, CHIRP down: the envelope peak of a fast
 *      chirp lags the resonance by about the same amount in either direction, so the
 *      mean of the two peak frequencies is the coarse resonance f_c. Over-amplitude
 *      aborts a chirp and it is repeated at a quarter of the force; too small a peak
 *      repeats it with more force.
 *   2. RINGDOWN at f_c: excite, stop, follow the free decay to 1/e: the time constant
 *      tau = 2Q/wn (6-12) gives Q_rd = pi f tau, the rotation of the LMSD phasor gives
 *      the free frequency f_d.
 *      The decay is followed to 1/e or for at most 8 s; tau from the log-amplitude
 *      slope. At high Q it is followed a second time, unexcited, with the NCO at the
 *      free frequency found (the first was seen off frequency from f_c). Above tau = 0.25 s (high Q) the ring-down is the identification (f0 from
 *      the free frequency, Q from tau), a Q beyond SELFCAL_Q_FIXED_MAX fails with the
 *      reason, and else one point at f0 settled for 6 tau gives |H(wn)|, arg H(wn)
 *      for step 4 (2Q/wn per step would be 21 s at Q = 10^5).
 *   3. STEPS: 9 points at f_d + {-2,-1.5,-1,-0.5,0,0.5,1,1.5,2} f_d/(2 Q_rd), each
 *      settled for 7 tau, averaged 0.1 s, at a force that puts the peak at amp_meas_v; the linear
 *      least-squares fit of selfcal_fit.h (known converter delay of 1.5 samples plus up
 *      to 8 samples of unknown analog-chain delay, searched) gives wn, Q, |H(wn)| and
 *      arg H(wn). If the
 *      fit moves the centre by more than a quarter bandwidth or Q by more than 20 %, the
 *      points are placed again around the fit (once).
 *   4. HOLD at wn with the force phase P = phase_set - arg H(wn) and the force
 *      amplitude_set / |H(wn)| for 6 tau: the vibration is then at the loop's set point,
 *      and the loops start from that excitation (bumpless).
 * Then READY: the application stages drive.freq_hz = drive.cal_f0_hz = wn/2pi,
 * drive.cal_q, drive.cal_gain_v_per_v2, drive.p_init_deg through the parameter bank
 * and requests the hand-over (SWEEP -> ACQUIRE).
 *
 * The sense mode (cfg.sense 1, sense.cal): identified by the same chain before the drive's,
 * through the feedback electrodes (their own synthesis, sense.fb_scheme) and the sense
 * pickoff's LMSD, with the drive electrodes at 0 V. The drive rests because the sense
 * excitation needs the NCO across the sense resonance, and because the drive's motion
 * puts its quadrature on the sense pickoff: 1500 deg/s is several times the ADC's range
 * on a part near its match (issue 19), which the identification would clip on.
 *   S1. QUIET for the drive's ring-down (the stored drive model's tau, capped), then the
 *       drive's steps 1-3 over the sense search range: chirps, ring-down, stepped points
 *       and the fit of selfcal_fit.h (or, at high Q, the ring-down's f0 and Q). The
 *       sense mode's gain at its resonance is not needed.
 *   S2. Tuning slope (cfg.tune_probe_v > 0): two ring-downs excited at the sense f0,
 *       their decays followed with the tuning electrodes at 0 V and at Vt. The tuning
 *       pair softens the sense spring, ws^2 = ws0^2 - ke Vt^2 (issue 19; a parallel-plate
 *       pair, 6-3), so ke = (wd0^2 - wd1^2) / Vt^2 (the damping term of wd^2 = wn^2 -
 *       sigma^2 is the same in both). Applying Vt only during the decay needs no search
 *       for the moved resonance: the free oscillation shows its own frequency.
 *   S3. After the drive's resonance is identified (before its hold: the drive is again
 *       at rest): the feedback force's response at the drive frequency, H_s(wc), from
 *       three settled means at wc, unexcited, excited, unexcited (the drive's remaining
 *       vibration, a slow decay at wc, cancels in the excited mean less the mean of the
 *       others). The means last whole periods of the sense mode's beat against wc
 *       (|fd_s - wc|): the transient of switching the force on or off rings at the
 *       sense's own frequency and averages out.
 *   S4. Mode tuning (cfg.tune_mode 1 or 2, sense_tune.h), after S3's quiet and before its
 *       means: the voltage that puts the untuned free frequency (S2's at 0 V) at the
 *       drive's resonance (plus the split), from S2's slope; a ring-down at that voltage
 *       (held through the excitation and the decay) shows where the resonance went; the
 *       slope is refined from it (a secant on Vt^2, since ws^2 is linear in Vt^2) and the
 *       voltage recomputed, until the free frequency is within a quarter of the sense
 *       half-bandwidth of the target, or of one DAC code's move when that is coarser
 *       (at most SC_MATCH_PASSES ring-downs). S3 then measures H_s(wc) at that voltage,
 *       and sense.f0_hz, sense.q are the tuned mode's. A target at or above the untuned
 *       resonance (tuning only lowers it), a voltage beyond cfg.tune_v_max_v, no slope
 *       (no electrodes, or S2 failed) or no convergence: S4 fails with its reason
 *       (match_why), S3 runs untuned and nothing of the tuning is staged.
 * The force-rebalance model (sense_fr.h) then follows: sense.f0_hz, sense.q from S1;
 * sense.fb_gain_v_per_v2 = +-|H_s(wc)| and sense.fb_phase_deg = theta such that a
 * feedback command lands on the real axis of the rate frame R = S e^{-j psi} / A_set,
 * psi = phase_set + phi_dm (rate_channel.h): the force at P + theta gives R =
 * H_s e^{j (P + theta - psi)} / A_set with P = phase_set - arg H_d(wc) at lock, so
 *     theta = phi_dm + arg H_d(wc) - arg H_s(wc),
 * taken within +-90 deg (the Coriolis force's side; the gain carries the sign). phi_dm is
 * rate.demod_phase_deg when the sweep runs: the calibration flow's later one needs the
 * sweep again. sense.cal_tune_ke_per_s2_per_v2 from S2.
 * A sense mode that cannot be identified (no resonance in the range, Q below 2 for the
 * stepped plan, points that do not fit a resonance, as on a part whose feedback pair is
 * not the one sense.fb_scheme drives, no response at wc) ends the sense part with its
 * reason (selfcal_sense_t.why) and the drive's identification goes on: the sense.*
 * values are then not staged (all four or none: a loop designed from a mix would be
 * neither part's), and status says why. The thesis's Q = 3 at 2 kHz is identified by
 * the stepped fit (1.3..2.7 kHz), but its ring-down lasts 24 samples: S2 reports that
 * and stages no tuning slope (tests/closed_loop/test_cl_sense_id.c).
 */
#ifndef SELFCAL_H
#define SELFCAL_H

#include <stdint.h>

#include "gyro/selfcal_exec.h"
#include "gyro/selfcal_fit.h"

/* The fixed-frequency drive's reach (the thesis's drive: fixed NCO frequency, phase PI
 * on the force phase): its phase PI's proportional gain grows as Q and the drive phase
 * keeps its temperature sensitivity only within about +-1/(Q kET) K, +-5 K at Q = 5000.
 * Q = 5000 is the highest Q at which the self-calibrated fixed drive is shown to lock
 * (tests/slow/test_integrity_selfcal.c); at Q = 10^4 it never locks. A sweep that
 * identifies a higher Q (or that runs with drive.track 1 and a tau beyond the stepped
 * plan's) identifies |H(wn)| by a burst (selfcal.c: post_burst) instead of a settled
 * point, hands over to the tracking drive and commits drive.track 1 (track). */
#define SELFCAL_Q_FIXED_MAX 5000.0

typedef struct {
  double fs_hz;
  double f_lo_hz, f_hi_hz; /* search range of the resonance */
  double chirp_hz_per_s;
  double quiet_s;        /* ring-down wait before each chirp */
  double amp_max_v;      /* back-off threshold: 50 % of the ADC range */
  double amp_meas_v;     /* peak amplitude aimed at by the measurements */
  double f_cmd_start_v2; /* first chirp force (low) */
  double f_cmd_max_v2;   /* what the drive synthesis can deliver */
  double amp_set_v;
  uint32_t track;
  /* drive.track at the start: 1 keeps the tracking drive at any Q */ /* the amplitude loop's set point */
  double phase_set_rad; /* the phase loop's set point */
  double delay_s;       /* DAC latency + zero-order hold: 1.5 samples */
  /* The sense mode's identification (header: S1-S3) */
  uint32_t sense;              /* 1: identify the sense mode too */
  double s_f_lo_hz, s_f_hi_hz; /* its search range */
  double s_f_cmd_start_v2;     /* first chirp force on the feedback pair */
  double s_f_cmd_max_v2;       /* what the feedback synthesis can deliver */
  double s_quiet_s;            /* the drive's ring-down before S1 */
  double tune_probe_v;         /* S2's tuning voltage; 0: no S2 */
  double demod_phase_rad;      /* rate.demod_phase_deg, phi_dm (S3) */
  uint32_t tune_mode;          /* S4: sense.tune (0 none, 1 matched, 2 split); sense 1 only */
  double tune_split_hz;        /* S4: sense.tune_split_hz */
  double tune_v_max_v;         /* S4: sense.tune_v_max_v */
  double amp_clip_v;           /* S3's back-off threshold: near the ADC's range */
} selfcal_cfg_t;

typedef enum {
  SELFCAL_IDLE = 0,
  SELFCAL_WAIT_SWEEP,
  SELFCAL_QUIET_UP,
  SELFCAL_CHIRP_UP,
  SELFCAL_QUIET_DOWN,
  SELFCAL_CHIRP_DOWN,
  SELFCAL_RINGDOWN,
  SELFCAL_FINE,
  SELFCAL_HOLD,
  SELFCAL_READY,
  SELFCAL_DONE,
  SELFCAL_FAILED,
  SELFCAL_REBURST,     /* a burst went over the ADC budget: the vibration decays, drive off */
  SELFCAL_SENSE_TUNE,  /* S2: a ring-down of the sense mode with or without Vt */
  SELFCAL_SENSE_QUIET, /* S3: the drive's ring-down before the points at wc */
  SELFCAL_SENSE_WC,    /* S3: the three means at wc */
  SELFCAL_SENSE_MATCH  /* S4: a ring-down of the sense mode at the tuning voltage */
} selfcal_state_t;

/* The sense mode's identification (header: S1-S3). */
typedef enum {
  SELFCAL_SENSE_OFF = 0, /* not asked (cfg.sense 0) */
  SELFCAL_SENSE_RUN,     /* S1 running */
  SELFCAL_SENSE_F0,      /* S1 done: f0, Q; S3 to come */
  SELFCAL_SENSE_OK,      /* all four model values identified */
  SELFCAL_SENSE_FAILED   /* why: nothing staged */
} selfcal_sense_state_t;

typedef enum {
  SELFCAL_TUNE_OFF = 0, /* not probed (tune_probe_v 0, or S1 failed) */
  SELFCAL_TUNE_OK,      /* ke identified (0: the probe moved nothing: no electrodes) */
  SELFCAL_TUNE_FAILED   /* tune_why: not staged */
} selfcal_tune_state_t;

typedef struct {
  selfcal_sense_state_t state;
  const char *why;
  double f0_hz, q, rms_rel; /* S1 (rms_rel 0: the ring-down's identification) */
  double gain_pk_v_per_v2;  /* S1: |H_s| at f0, for the forces of S2 and S3 */
  double h_re, h_im;        /* S3: H_s(wc), sense phasor per V^2 at force phase 0 */
  double fb_gain_v_per_v2;  /* +-|H_s(wc)| */
  double fb_phase_rad;      /* theta */
  selfcal_tune_state_t tune;
  const char *tune_why;
  double tune_fd0_hz, tune_fd1_hz; /* S2's free frequencies, tuning at 0 V and at Vt */
  double tune_ke_per_s2_per_v2;
  /* S4 (cfg.tune_mode): the sense resonance tuned to its target */
  selfcal_tune_state_t match; /* OFF: not asked; FAILED: match_why, nothing of it staged */
  const char *match_why;
  double match_target_hz; /* the drive's resonance, plus the split */
  double match_v;         /* the tuning voltage (its DAC code's) */
  double match_fd_hz;     /* the last ring-down's free frequency at match_v */
  double match_ke;        /* the slope refined by the ring-downs (secant on Vt^2) */
  uint32_t match_passes;  /* ring-downs at a tuning voltage */
  uint32_t ticks;         /* the sense identification's length (its jobs), samples */
} selfcal_sense_t;

/* Every STEPS point of the latest sweep (both placements when the points were placed
 * again around a first fit), kept for export (`sweep points`): the drive LMSD phasor Z
 * averaged at the NCO half-step with the force command it had (force phase 0, so
 * H = Z / f_cmd). Filled by the background as the results arrive; cleared when a sweep
 * starts. */
#define SELFCAL_EXPORT_MAX (2u * SELFCAL_MAX_PTS)

typedef struct {
  uint32_t half_step; /* NCO half-rate phase step: f = 2 half_step fs / 2^32 (nco.h) */
  float z_re, z_im;   /* mean drive LMSD phasor, V */
  float f_cmd_v2;     /* force command during the average, Ks*V^2 */
  uint32_t stage;     /* 1: first placement, 2: placed again around the first fit */
} selfcal_export_pt_t;

typedef struct {
  selfcal_cfg_t cfg;
  selfcal_exec_t *x;
  selfcal_state_t state;
  double f_cmd_v2;
  double f_up_hz, f_down_hz, f_coarse_hz, chirp_peak_v;
  double rd_f_hz, rd_q, rd_gain;
  double plan_f_hz, plan_hb_hz; /* centre and half bandwidth of the steps */
  selfcal_fit_t fit;
  double delay_s; /* total chain delay found by the fit */
  double hold_f_cmd_v2, hold_p_rad;
  float f0_hz_f;  /* wn/2pi as the float parameter value */
  uint32_t ticks; /* sweep length so far, samples */
  uint32_t retries, refits;
  uint32_t rd_passes; /* ring-downs followed (high Q: a second one on frequency) */
  uint32_t one_point; /* the high-Q plan: ring-down identification, one point */
  uint32_t burst;     /* ... that point by a burst (post_burst) */
  uint32_t track;     /* hand over to the tracking drive (drive.track 1) */
  uint32_t braked;    /* tracking hand-over: 1 braking the burst's vibration, 2 done */
  double burst_end_v; /* |Z| where the burst left the vibration */
  const char *why;    /* reason of FAILED */
  /* selfcal_watch: the state last seen, since when (caller's ticks), and how long the
   * posted job may take (samples). */
  selfcal_state_t watch_state;
  uint32_t watch_t0, job_bound_ticks;
  selfcal_export_pt_t pts[SELFCAL_EXPORT_MAX];
  uint32_t n_pts;
  /* The sense mode's identification: the chain above runs on the sense channel while
   * sense_phase is 1 (S1); resume is the drive's step S3 interrupted (1 hold, 2 one
   * point, 3 burst); tune_pass the S2 ring-down under way (0 at 0 V, 1 at Vt). */
  uint32_t sense_phase, resume, tune_pass;
  uint16_t match_code; /* S4: the tuning voltage's DAC code the jobs hold (S3 too) */
  selfcal_sense_t sense;
} selfcal_t;

/* Bind to the ISR half. Returns 0, or -1 for NULL. State IDLE. */
int selfcal_init(selfcal_t *s, selfcal_exec_t *x);
/* Begin (the application has requested SWEEP). Returns 0, or -1 (nothing changed) for
 * a bad configuration or a sweep already running. */
int selfcal_start(selfcal_t *s, const selfcal_cfg_t *cfg);
/* One background pass. sweeping: the ISR is in SWEEP and has taken the request. A sweep
 * that stops being active before READY fails. Returns the state after the pass. */
selfcal_state_t selfcal_background(selfcal_t *s, int sweeping);
/* The application's verdict on READY: ok -> DONE, else FAILED with why. */
void selfcal_finish(selfcal_t *s, int ok, const char *why);
/* Stop a running sweep (a drive command took the drive): FAILED with why. */
void selfcal_abort(selfcal_t *s, const char *why);
/* Timeouts, from the background with a sample counter: a sweep that stays in one state
 * longer than that state can take fails (the request never taken: 0.1 s; a job that never
 * reports: twice its planned length plus 1 s; READY never committed: 1 s), so a sweep
 * can never hold the sequencer busy. */
void selfcal_watch(selfcal_t *s, uint32_t now_ticks);
int selfcal_running(const selfcal_t *s);
/* Measured points of the latest sweep for export: the number held (0 while a sweep runs
 * or before any sweep measured; a failed sweep keeps what it measured), and the
 * frequency of a point's half-step in Hz. */
uint32_t selfcal_export_count(const selfcal_t *s);
double selfcal_export_f_hz(const selfcal_t *s, uint32_t i);
const char *selfcal_state_name(selfcal_state_t st);
/* S4's calibration of the temperature hold (sense_tune.h): the untuned resonance that,
 * with the refined slope, gives back S4's own voltage for the target,
 * sqrt(f_t^2 + ke Vt^2 / (4 pi^2)). Not the measured one: the hold must reproduce, at the
 * reference, the very voltage (DAC code) the force-rebalance model was measured at (S3),
 * since one code moves a matched resonance by most of a half-bandwidth at Q 1e4
 * (test_cl_sense_tune.c). 0 unless S4 tuned the part. */
double selfcal_match_s0_hz(const selfcal_sense_t *m);

#endif /* SELFCAL_H */
