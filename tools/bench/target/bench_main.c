/* gyro-bench-qemu: instruction counts of the sample-path kernels, gyro_tick and the
 * whole sample interrupt on QEMU's netduinoplus2 (STM32F405, Cortex-M4F), run as
 *     qemu-system-arm -M netduinoplus2 -nographic -monitor none -icount shift=0 \
 *         -semihosting-config enable=on,target=native -kernel gyro-bench-qemu.elf
 * (tools/bench/run-bench does this). Results go out as lines on the semihosting console
 * and the image ends with a semihosting exit; tools/bench/run-bench parses the lines:
 *   calib nops=100 delta=D            D must be 100: one count per instruction
 *   case NAME n=N k_sum= k_min= k_max= b_sum= b_min= b_max= locked=L
 *     (k: counter deltas around the kernel call, b: around an empty call, same loop)
 *   done | error WHAT CODE
 *
 * Besides the kernels (tools/bench/common), it counts:
 *   app_sample_isr      called directly, with the board HAL's DAC write (its ADC frame
 *                       read where the DMA leaves it; the self-measurement is the
 *                       handler's)
 *   isr_app_cb          the real DMA2_Stream0_IRQHandler pended through the NVIC, its
 *                       callback being bench_cb = app_sample_isr + clearing the fake
 *                       TCIF; baseline: an IRQ whose handler is a lone BX LR
 *   isr_empty_cb        the same with bench_cb_empty (handler alone + wrapper)
 *   cb_wrap             bench_cb_empty against bench_empty, called directly: the cost of
 *                       the wrapper, subtracted by run-bench
 * The application runs with every loop on: the continuous self-test is switched on
 * before the counts. The semihosting command line (-append) selects the mode: "quick"
 * runs fewer iterations; "trace" runs only the application's pended sample interrupts,
 * for an instruction trace (QEMU -singlestep -d exec,nochain) that
 * tools/bench/isr_trace.py turns into a per-function breakdown and a cycle estimate, in
 * this order (each an irq case, its interrupts in a row):
 *   isr_app_cb          LOCKED, BENCH_N_TRACE interrupts (the steady state)
 *   isr_track           the same drive switched to the tracking drive (drive.track 1:
 *                       its PLL, the position-form amplitude PI and their notches),
 *                       BENCH_N_TRACE interrupts
 *   isr_fr              force rebalance added (sense.mode 1; the continuous self-test
 *                       on, its force in the loop's command), BENCH_N_TRACE interrupts
 *   isr_fault           a NaN planted in the drive demodulator: the fault's tick, the
 *                       loop state's clear and the ticks after it
 *   isr_sweep_chirp     SWEEP: the self-calibration executive (selfcal_exec.h) on a
 *   isr_sweep_ringdown  chirp, a ring-down and a stepped-sine job, each posted here as
 *   isr_sweep_steps     the background sequencer would post it
 * and "state" lines with the mode and the rate's validity before each. */
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "app/app.h"
#include "bench_isr_board.h"
#include "bench_kernels.h"
#include "bench_now.h"
#include "bench_plant.h"
#include "dsp/ramfunc.h"
#include "hal/hal_board_temp.h"
#include "hal/hal_sample_timer.h"
#include "stm32f4_board.h"
#include "stm32f4_core.h"
#include "cm4_fault.h"
#include "stm32f4_regs.h"

#define BENCH_N_FULL 2000u
#define BENCH_N_QUICK 200u
#define BENCH_FS_HZ BOARD_SAMPLE_RATE_HZ
#define BENCH_SPARE_IRQ 57u /* DMA2 stream 1: unused by the port; the baseline IRQ */
#define BENCH_WARMUP_MAX 400000u
#define BENCH_SETTLE 5000u
#define BENCH_N_TRACE 100u     /* traced ISRs: ten rate-filter ticks, one P-filter tick */
#define BENCH_N_TRACE_MODE 40u /* traced ISRs of each other mode: four blocks */
/* LOCKED ticks before the trace: 2 s, so that the thermometer's fast start after lock is
 * over (P_f's held value weighs under COMP_FILTERS_HELD_W_MAX after about 1.2 s): the
 * compensation's filters step, the slew windows are judged and the shadow runs, as in
 * the steady state (with 10 ms, as before, none of them was in the trace). */
#define BENCH_SETTLE_TRACE 100000u

#define SYS_WRITE0 0x04u
#define SYS_GET_CMDLINE 0x15u
#define SYS_EXIT 0x18u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u
#define ADP_STOPPED_RUNTIME_ERROR 0x20023u

/* ---- semihosting (QEMU -semihosting-config enable=on,target=native) ---- */

static uint32_t semihost(uint32_t op, const void *arg)
{
  register uint32_t r0 __asm__("r0") = op;
  register const void *r1 __asm__("r1") = arg;
  __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

typedef struct {
  char buf[200];
  size_t len;
} line_t;

static void put_str(line_t *l, const char *s)
{
  while (*s != '\0' && l->len + 1u < sizeof l->buf) l->buf[l->len++] = *s++;
}

static void put_u64(line_t *l, uint64_t v)
{
  char tmp[20];
  size_t n = 0u;
  do {
    tmp[n++] = (char)('0' + (char)(v % 10u));
    v /= 10u;
  } while (v != 0u);
  while (n > 0u && l->len + 1u < sizeof l->buf) l->buf[l->len++] = tmp[--n];
}

static void put_kv(line_t *l, const char *k, uint64_t v)
{
  put_str(l, " ");
  put_str(l, k);
  put_str(l, "=");
  put_u64(l, v);
}

static void emit(line_t *l)
{
  put_str(l, "\n");
  l->buf[l->len] = '\0';
  (void)semihost(SYS_WRITE0, l->buf);
  l->len = 0u;
}

static void report(const char *name, const bk_result_t *r)
{
  line_t l = {{0}, 0u};
  put_str(&l, "case ");
  put_str(&l, name);
  put_kv(&l, "n", r->kern.n);
  put_kv(&l, "k_sum", r->kern.sum);
  put_kv(&l, "k_min", r->kern.min);
  put_kv(&l, "k_max", r->kern.max);
  put_kv(&l, "b_sum", r->base.sum);
  put_kv(&l, "b_min", r->base.min);
  put_kv(&l, "b_max", r->base.max);
  put_kv(&l, "locked", r->locked);
  emit(&l);
}

static void fail(const char *what, int code)
{
  line_t l = {{0}, 0u};
  put_str(&l, "error ");
  put_str(&l, what);
  put_kv(&l, "code", (uint64_t)(uint32_t)code);
  emit(&l);
  (void)semihost(SYS_EXIT, (const void *)ADP_STOPPED_RUNTIME_ERROR);
  for (;;) {
  }
}

typedef enum { MODE_FULL, MODE_QUICK, MODE_TRACE } bench_mode_t;

static bench_mode_t bench_mode(void)
{
  static char cmd[512]; /* "<image path> <mode>" */
  struct {
    char *buf;
    uint32_t len;
  } blk = {cmd, sizeof cmd - 1u};
  if (semihost(SYS_GET_CMDLINE, &blk) != 0u) return MODE_FULL;
  cmd[sizeof cmd - 1u] = '\0';
  if (strstr(cmd, "trace") != NULL) return MODE_TRACE;
  return strstr(cmd, "quick") != NULL ? MODE_QUICK : MODE_FULL;
}

/* ---- board bring-up for the bench: QEMU has no RCC, so no clock tree; no DWT ---- */

void board_system_init(void) { cm4_fault_enable(); }

/* QEMU's netduinoplus2 has no I2C peripheral behind its register window, and the bench
 * measures the sample interrupt: the board temperature sensor is absent here (the
 * fusion is background work, board_therm.h). */
int hal_board_temp_start(void) { return -1; }
hal_board_temp_event_t hal_board_temp_poll(int16_t *code)
{
  (void)code;
  return HAL_BOARD_TEMP_ABSENT;
}

static void counter_init(void)
{
  TIM2->CR1 = 0u;
  TIM2->PSC = 0u;
  TIM2->ARR = 0xFFFFFFFFu;
  TIM2->CR1 = TIM_CR1_CEN;
}

/* Two counter reads back to back, and with 100 NOPs between them, in one asm block each
 * so that the compiler cannot put anything else in between: the difference must be 100. */
static uint32_t reads_around(int nops)
{
  volatile uint32_t *cnt = &TIM2->CNT;
  uint32_t t0, t1;
  if (nops != 0) {
    __asm__ volatile("ldr %0, [%2]\n .rept 100\n nop\n .endr\n ldr %1, [%2]"
                     : "=&r"(t0), "=&r"(t1)
                     : "r"(cnt)
                     : "memory");
  } else {
    __asm__ volatile("ldr %0, [%2]\n ldr %1, [%2]"
                     : "=&r"(t0), "=&r"(t1)
                     : "r"(cnt)
                     : "memory");
  }
  return t1 - t0;
}

static void calibrate(void)
{
  const uint32_t d0 = reads_around(0);
  const uint32_t d100 = reads_around(1);
  line_t l = {{0}, 0u};
  put_str(&l, "calib");
  put_kv(&l, "nops", 100u);
  put_kv(&l, "delta", (uint64_t)(d100 - d0));
  emit(&l);
}

/* ---- the application and its sample interrupt ---- */

/* Where the product keeps it (hal/boards/ref_f405/main/main_board.c). */
static STM32F4_CCM_BSS app_t s_app;
static bench_plant_t s_plant;
static uint32_t s_n; /* iterations per case */
static int s_each;   /* trace mode: print every interrupt's count */

typedef void (*isr_fn)(void *);

/* The wrappers sit in SRAM with the sample path, so that they call it as the product's
 * handler does, without a linker veneer between flash and SRAM. */
GYRO_RAMFUNC __attribute__((noipa)) static void bench_empty(void *ctx) { (void)ctx; }

GYRO_RAMFUNC __attribute__((noipa)) static void bench_cb(void *ctx)
{
  app_sample_isr(ctx);
  bench_board_clear_tc();
}

GYRO_RAMFUNC __attribute__((noipa)) static void bench_cb_empty(void *ctx)
{
  bench_empty(ctx);
  bench_board_clear_tc();
}

static void next_frame(void)
{
  hal_adc_frame_t adc;
  bench_plant_frame(&s_plant, &s_app.gyro, &adc);
  bench_board_set_frame(&adc);
}

/* Direct calls: app_sample_isr vs an empty call; bench_cb_empty vs bench_empty. */
__attribute__((noipa)) static uint32_t run_direct(isr_fn fn, uint32_t n, bk_stat_t *st)
{
  uint32_t locked = 1u;
  for (uint32_t i = 0u; i < n; i++) {
    next_frame();
    const uint32_t t0 = bk_now();
    fn(&s_app);
    const uint32_t t1 = bk_now();
    bk_stat_add(st, t1 - t0);
    if (s_app.gyro.sup.mode != GYRO_MODE_LOCKED) locked = 0u;
  }
  return locked;
}

__attribute__((noipa)) static void bench_spare_handler(void) {}

/* Pend irq through the NVIC and count from just before to just after the interrupt. */
__attribute__((noipa)) static uint32_t run_irq(uint32_t irq, uint32_t n, bk_stat_t *st)
{
  uint32_t locked = 1u;
  for (uint32_t i = 0u; i < n; i++) {
    next_frame();
    bench_board_arm();
    const uint32_t t0 = bk_now();
    NVIC->ISPR[irq >> 5] = 1u << (irq & 31u);
    cm4_dsb();
    cm4_isb();
    const uint32_t t1 = bk_now();
    bk_stat_add(st, t1 - t0);
    if (s_app.gyro.sup.mode != GYRO_MODE_LOCKED) locked = 0u;
    if (s_each) {
      line_t l = {{0}, 0u};
      put_str(&l, "irq");
      put_kv(&l, "i", i);
      put_kv(&l, "delta", t1 - t0);
      emit(&l);
    }
  }
  return locked;
}

static void put_state(const char *name)
{
  line_t l = {{0}, 0u};
  put_str(&l, "state ");
  put_str(&l, name);
  put_kv(&l, "mode", (uint32_t)s_app.gyro.sup.mode);
  put_kv(&l, "rate_invalid", s_app.gyro.out.rate_invalid);
  emit(&l);
}

static void start_chain(isr_fn cb)
{
  const int rc = hal_sample_timer_start(BENCH_FS_HZ, cb, &s_app);
  if (rc != 0) fail("hal_sample_timer_start", rc);
}

static void direct_case(const char *name, isr_fn fn)
{
  bk_result_t r;
  bk_stat_reset(&r.kern);
  bk_stat_reset(&r.base);
  r.locked = run_direct(fn, s_n, &r.kern);
  (void)run_direct(bench_empty, s_n, &r.base);
  if (fn != app_sample_isr) r.locked = 0u;
  report(name, &r);
}

static void irq_case_n(const char *name, isr_fn cb, uint32_t n)
{
  bk_result_t r;
  start_chain(cb);
  bk_stat_reset(&r.kern);
  bk_stat_reset(&r.base);
  r.locked = run_irq(STM32F4_IRQ_DMA2_STREAM0, n, &r.kern);
  (void)run_irq(BENCH_SPARE_IRQ, n, &r.base);
  if (cb != bench_cb) r.locked = 0u;
  report(name, &r);
  hal_sample_timer_stop();
}

static void irq_case(const char *name, isr_fn cb) { irq_case_n(name, cb, s_n); }

static void stage_param(const char *name, param_value_t val)
{
  const param_idx_t i = param_lookup(name, strlen(name));
  if (i >= PARAM_COUNT || params_stage(&s_app.params, i, val) != PARAM_OK) fail(name, -1);
}

/* Every loop on: the continuous self-test too (it is off by default). It needs an
 * expectation, which the generic defaults leave 0 (a part's calibration measures it):
 * any nonzero one lets it run, and the bench measures its cost, not its verdict. The
 * temperature compensation as the calibration flow sets it (three stages of the slow
 * thermometer and the fast path, whose blend has its cost on the P slot). Quadrature
 * nulling on (its update on the new P_f's P slot). All in one commit: the bank takes one
 * change per tick. */
static void continuous_selftest_on(void)
{
  param_value_t val;
  val.f = 1.0f;
  stage_param("selftest.cont_expect_dps", val);
  val.f = 15.0f;
  stage_param("rate.comp_tau_s", val);
  val.f = 5.0f;
  stage_param("rate.comp_fast_tau_s", val);
  val.u = 3u;
  stage_param("rate.comp_stages", val);
  val.u = 1u;
  stage_param("quad.null", val);
  stage_param("selftest.continuous", val);
  params_err_t err;
  if (params_commit(&s_app.params, &err) != PARAM_OK) fail("selftest.continuous", -1);
}

/* A job for the self-calibration executive, posted as the background sequencer posts
 * one (selfcal_exec.h: job, then job_seq + 1). */
static void post_job(uint32_t kind)
{
  selfcal_exec_t *x = &s_app.gyro.cal;
  selfcal_job_t j;
  memset(&j, 0, sizeof j);
  j.kind = kind;
  j.n_pts = 3u;
  for (uint32_t k = 0u; k < 3u; k++) j.half_step[k] = s_app.gyro.nco.half_step + 2000u * k;
  j.chirp_delta = 1;
  j.chirp_ticks = 100000u;
  j.settle_ticks = j.step_settle_ticks = 5u;
  j.avg_ticks = 100000u;
  j.f_cmd_v2 = 50.0f;
  j.p_rad = 0.4f;
  j.amp_max_v = 4.0f;
  j.amp_target_v = 4.0f;
  memset(&x->res, 0, sizeof x->res); /* as selfcal_exec_post does */
  x->job = j;
  atomic_store(&x->job_seq, atomic_load(&x->job_seq) + 1u);
}

/* The quadrature-nulling loop's costliest update inside the traced LOCKED ticks (one in
 * 100): its probe's last, which takes the second mean, divides for the gain and closes
 * the loop (the bench's plant has no nulling electrodes, so its own probe failed long
 * before: the state is set as the probe leaves it, with a credible step). The tracking
 * drive's trace then runs the closed loop's update. */
static void quad_null_probe_ends(void)
{
  quad_null_t *q = &s_app.gyro.quad;
  const quad_null_design_t *qd = &s_app.gyro.design->quad;
  quad_null_start(qd, q);
  q->mode = QUAD_NULL_PROBE_STEP;
  q->count = qd->wait_updates + qd->avg_updates - 1u;
  q->base_dps = s_app.gyro.rate.quad_dps - 100.0f;
}

/* The tracking drive (drive.track 1) takes over the running drive, as a design change
 * would hand it over; its own rarer ticks (the self-test's verdict, a slew window's end)
 * are put inside the traced interrupts as for the fixed drive. */
static gyro_design_t s_track_design;
static void trace_tracking(void)
{
  param_values_t v = *params_current(&s_app.params);
  v.drive_track = 1u;
  if (gyro_design(&v, &s_track_design) != GYRO_DESIGN_OK) fail("track_design", -1);
  gyro_apply(&s_app.gyro, &s_track_design);
  s_app.gyro.selftest.cont_blocks = s_track_design.selftest.cont_settle_blocks;
  s_app.gyro.valid.p_updates = RATE_VALID_SLEW_UPDATES - 1u;
  put_state("isr_track");
  irq_case_n("isr_track", bench_cb, BENCH_N_TRACE);
}

/* Force rebalance (sense.mode 1) on the tracking drive with quadrature nulling and the
 * continuous self-test (its force in the loop's command, selftest.h), every closed-sense
 * loop built so far: the feedback pair's waveform each tick and the loop's update steps
 * over the block. (Mode tuning costs the sample path nothing: its voltage comes as a
 * request, app_tune.h.) The sense model is the closed-loop test's part (Q 1e4 at
 * 1600 Hz); the bench's plant has no feedback electrodes, so the loop runs to its
 * limit, its costlier path. */
static gyro_design_t s_fr_design;
static void trace_force_rebalance(void)
{
  param_values_t v = *params_current(&s_app.params);
  v.drive_track = 1u;
  v.sense_mode = 1u;
  v.selftest_continuous = 1u;
  v.sense_f0_hz = 1600.0f;
  v.sense_q = 1.0e4f;
  v.sense_fb_gain_v_per_v2 = 0.46f;
  if (gyro_design(&v, &s_fr_design) != GYRO_DESIGN_OK) fail("fr_design", -1);
  gyro_apply(&s_app.gyro, &s_fr_design);
  s_app.gyro.selftest.cont_blocks = s_fr_design.selftest.cont_settle_blocks;
  s_app.gyro.valid.p_updates = RATE_VALID_SLEW_UPDATES - 1u;
  put_state("isr_fr");
  irq_case_n("isr_fr", bench_cb, BENCH_N_TRACE);
  gyro_apply(&s_app.gyro, &s_track_design); /* the fault and SWEEP traced as before */
}

/* The rarer ticks (trace mode): a fault and its clear, then SWEEP's jobs. */
static void trace_other_modes(void)
{
  s_app.gyro.lmsd_drive.w_i = __builtin_nanf("");
  put_state("isr_fault");
  irq_case_n("isr_fault", bench_cb, BENCH_N_TRACE_MODE);
  gyro_sweep_begin(&s_app.gyro);
  static const struct {
    uint32_t kind;
    const char *name;
  } jobs[] = {{SELFCAL_JOB_CHIRP, "isr_sweep_chirp"},
              {SELFCAL_JOB_RINGDOWN, "isr_sweep_ringdown"},
              {SELFCAL_JOB_STEPS, "isr_sweep_steps"}};
  for (size_t k = 0u; k < sizeof jobs / sizeof jobs[0]; k++) {
    post_job(jobs[k].kind);
    put_state(jobs[k].name);
    irq_case_n(jobs[k].name, bench_cb, BENCH_N_TRACE_MODE);
  }
}

/* The application at lock, then: app_sample_isr called directly; the wrapper cost;
 * the whole interrupt with bench_cb and with bench_cb_empty. In trace mode only the
 * interrupt with bench_cb (first, so that the trace's first interrupts are these) and
 * the wrapper cost, for the cross-check of the trace against the counter. */
static void bench_app(uint32_t settle, int trace)
{
  const int rc = app_init(&s_app);
  if (rc != 0) fail("app_init", rc);
  param_values_t v;
  param_values_defaults(&v);
  if (bench_plant_init(&s_plant, (const gyro_design_t *)s_app.applied, &v) != 0) {
    fail("plant_init", -1);
  }
  continuous_selftest_on();
  gyro_start(&s_app.gyro);
  uint32_t settled = 0u;
  for (uint32_t i = 0u; i < BENCH_WARMUP_MAX && settled < settle; i++) {
    next_frame();
    app_sample_isr(&s_app);
    settled = s_app.gyro.sup.mode == GYRO_MODE_LOCKED ? settled + 1u : 0u;
  }
  if (settled < settle) fail("app_not_locked", (int)s_app.gyro.sup.mode);

  /* Baseline interrupt: a spare vector with a lone BX LR, same priority. */
  volatile uint32_t *vtor = (volatile uint32_t *)(uintptr_t)SCB->VTOR;
  vtor[16u + BENCH_SPARE_IRQ] = (uint32_t)(uintptr_t)bench_spare_handler;
  cm4_dsb();
  cm4_nvic_enable(BENCH_SPARE_IRQ, STM32F4_PRIO_SAMPLE);

  if (trace) {
    /* The rarer LOCKED ticks inside the 100 traced: the continuous self-test judging
     * (after its LMS's settling time, longer than the warm-up), and a thermometer slew
     * window ending (once in RATE_VALID_SLEW_UPDATES P updates, one in 100 ticks). */
    s_app.gyro.selftest.cont_blocks = s_app.gyro.design->selftest.cont_settle_blocks;
    s_app.gyro.valid.p_updates = RATE_VALID_SLEW_UPDATES - 1u;
    quad_null_probe_ends();
    s_each = 1;
    put_state("isr_app_cb");
    irq_case("isr_app_cb", bench_cb);
    trace_tracking();
    trace_force_rebalance();
    trace_other_modes();
    s_each = 0;
    direct_case("cb_wrap", bench_cb_empty);
    return;
  }
  direct_case("app_sample_isr", app_sample_isr);
  direct_case("cb_wrap", bench_cb_empty);
  irq_case("isr_app_cb", bench_cb);
  irq_case("isr_empty_cb", bench_cb_empty);
}

int main(void)
{
  counter_init();
  const bench_mode_t mode = bench_mode();
  if (mode == MODE_TRACE) {
    s_n = BENCH_N_TRACE;
    bench_app(BENCH_SETTLE_TRACE, 1);
  } else {
    s_n = mode == MODE_QUICK ? BENCH_N_QUICK : BENCH_N_FULL;
    calibrate();
    const int rc = bk_setup();
    if (rc != 0) fail("bk_setup", rc);
    for (uint32_t id = 0u; id < (uint32_t)BK_COUNT; id++) {
      bk_result_t r;
      const int e = bk_run((bk_id_t)id, s_n, &r);
      if (e != 0) fail(bk_name((bk_id_t)id), e);
      report(bk_name((bk_id_t)id), &r);
    }
    bench_app(BENCH_SETTLE, 0);
  }
  line_t l = {{0}, 0u};
  put_str(&l, "done");
  emit(&l);
  (void)semihost(SYS_EXIT, (const void *)ADP_STOPPED_APPLICATION_EXIT);
  for (;;) {
  }
}
