/* demod-compare: the demodulator comparison of thesis 5.4.3 on the firmware kernels.
 *
 * Protocol: step input A sin(2 pi fc t) + n and AM input (A sin 2 pi fam t) sin(2 pi fc t)
 * + n, sigma_n = 0.002 Gaussian (seeded), fs = 50 kHz, fc = 1750 Hz, A = 0.01; every
 * demodulator's in-phase output through the same 4th-order 100 Hz Butterworth; N noise
 * realisations (the same noise for every demodulator). Reported per demodulator and
 * parameter set: steady-state MSE after the output filter, 2 % settling time of the mean
 * step response, gain and phase at 100 Hz of the mean AM response after the output
 * filter, and the measured -3 dB bandwidth of the demodulator alone (AM tones).
 * Two sets: the thesis's parameters, and each parameter tuned by bisection so that all
 * four demodulators have the same measured bandwidth.
 */
#define _POSIX_C_SOURCE 200809L

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <spawn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "demod_bank.h"
#include "dsp/biquad.h"
#include "dsp/butter.h"
#include "measure.h"
#include "signals.h"
#include "plant/plant_const.h"

extern char **environ;

static const double k_pi = PLANT_PI;

typedef struct {
  double fs_hz, fc_hz, amp, sigma, am_hz;
  double out_fc_hz;
  unsigned out_order;
  double settle_band;
  double t_ss_s, t_run_s; /* MSE and tone-fit window [t_ss, t_run) */
} protocol_t;

typedef struct {
  int runs;
  uint64_t seed;
  const char *json, *csv, *png;
  double bw_target_hz; /* <= 0: the measured bandwidth of LMSD at the thesis mu */
} opts_t;

typedef struct {
  const char *set;
  demod_t proto; /* initial state, copied for every run */
  double bw_hz;
  double sse, sse_raw;
  double *mean_step, *mean_am, *mean_raw; /* mean_raw: step, before the output filter */
  double mse_db, mse_raw_db, settle_s, settle_raw_s, gain, phase_deg;
} entry_t;

#define N_ENTRIES (2 * DK_COUNT)

static const double k_thesis_param[DK_COUNT] = {0.034, 0.982, 0.3, 0.0};

static void usage(const char *argv0)
{
  fprintf(stderr,
          "usage: %s [--runs N] [--seed S] [--bw-target HZ] [--json FILE] [--csv FILE]\n"
          "          [--png FILE]\n"
          "  --runs N        noise realisations (default 1000)\n"
          "  --seed S        noise seed (default 1)\n"
          "  --bw-target HZ  bandwidth of the equal-bandwidth set, 50..580 Hz (default: the\n"
          "                  measured bandwidth of LMSD at the thesis's mu = 0.034)\n"
          "  --json FILE     results as JSON\n"
          "  --csv FILE      mean responses: step and AM after the output filter, step\n"
          "                  before it (raw)\n"
          "  --png FILE      plot (python3 plot.py); writes FILE.json / FILE.csv beside it\n"
          "                  unless --json / --csv are given\n",
          argv0);
}

static int parse_args(int argc, char **argv, opts_t *o)
{
  *o = (opts_t){.runs = 1000, .seed = 1u};
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
    char *end = NULL;
    if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
      usage(argv[0]);
      exit(0);
    } else if (v == NULL) {
      fprintf(stderr, "%s: missing value\n", a);
      return -1;
    } else if (strcmp(a, "--runs") == 0) {
      const long n = strtol(v, &end, 10);
      if (*end != '\0' || n < 1 || n > 1000000) {
        fprintf(stderr, "--runs: expected 1..1000000, got '%s'\n", v);
        return -1;
      }
      o->runs = (int)n;
    } else if (strcmp(a, "--seed") == 0) {
      const unsigned long long s = strtoull(v, &end, 10);
      if (*end != '\0' || *v == '-') {
        fprintf(stderr, "--seed: expected an unsigned integer, got '%s'\n", v);
        return -1;
      }
      o->seed = (uint64_t)s;
    } else if (strcmp(a, "--bw-target") == 0) {
      const double f = strtod(v, &end);
      if (*end != '\0' || !(f >= MEAS_BW_MIN_HZ && f <= 580.0)) {
        fprintf(stderr, "--bw-target: expected %.0f..580 Hz, got '%s'\n", MEAS_BW_MIN_HZ, v);
        return -1;
      }
      o->bw_target_hz = f;
    } else if (strcmp(a, "--json") == 0) {
      o->json = v;
    } else if (strcmp(a, "--csv") == 0) {
      o->csv = v;
    } else if (strcmp(a, "--png") == 0) {
      o->png = v;
    } else {
      fprintf(stderr, "unknown option '%s'\n", a);
      return -1;
    }
    i++;
  }
  return 0;
}

static int output_filter(const protocol_t *p, biquad_cascade_t *lp)
{
  biquad_coeffs_t sec[BIQUAD_MAX_SECTIONS];
  const int n = butter_design(BUTTER_LOWPASS, p->out_order, p->out_fc_hz, 0.0, p->fs_hz, sec,
                              BIQUAD_MAX_SECTIONS);
  return (n > 0) ? biquad_cascade_init(lp, sec, (uint32_t)n) : -1;
}

/* Noise-free step through demodulator and output filter: its 2 % settling time. */
static double noise_free_settle(const protocol_t *p, const bench_t *b, const entry_t *e,
                                const biquad_cascade_t *lp0, size_t n)
{
  double *y = malloc(n * sizeof *y);
  if (y == NULL) {
    return NAN;
  }
  demod_t d = e->proto;
  biquad_cascade_t lp = *lp0;
  for (size_t k = 0; k < n; k++) {
    const float x = (float)(p->amp * b->carrier[k]);
    y[k] = biquad_cascade_step(&lp, demod_step(&d, x, b->ref_sin[k], b->ref_cos[k]));
  }
  const double t = settle_time_s(y, n, p->amp, p->settle_band, p->fs_hz);
  free(y);
  return t;
}

static void monte_carlo(const protocol_t *p, const opts_t *o, const bench_t *b,
                        const biquad_cascade_t *lp0, entry_t *ent, size_t n)
{
  float *noise = malloc(n * sizeof *noise);
  float *d_step = malloc(n * sizeof *d_step);
  float *d_am = malloc(n * sizeof *d_am);
  double *sig_step = malloc(n * sizeof *sig_step);
  double *sig_am = malloc(n * sizeof *sig_am);
  if (!noise || !d_step || !d_am || !sig_step || !sig_am) {
    fprintf(stderr, "out of memory\n");
    exit(1);
  }
  const double wm = 2.0 * k_pi * p->am_hz / p->fs_hz;
  for (size_t k = 0; k < n; k++) {
    sig_step[k] = p->amp * b->carrier[k];
    sig_am[k] = p->amp * sin(wm * (double)k) * b->carrier[k];
  }
  const size_t k_ss = (size_t)llround(p->t_ss_s * p->fs_hz);
  noise_rng_t g;
  noise_seed(&g, o->seed);
  for (int r = 0; r < o->runs; r++) {
    noise_fill(&g, noise, n, p->sigma);
    for (size_t k = 0; k < n; k++) {
      d_step[k] = (float)(sig_step[k] + (double)noise[k]);
    }
    noise_fill(&g, noise, n, p->sigma);
    for (size_t k = 0; k < n; k++) {
      d_am[k] = (float)(sig_am[k] + (double)noise[k]);
    }
    for (size_t i = 0; i < N_ENTRIES; i++) {
      entry_t *e = &ent[i];
      demod_t d = e->proto;
      biquad_cascade_t lp = *lp0;
      for (size_t k = 0; k < n; k++) {
        const float v = demod_step(&d, d_step[k], b->ref_sin[k], b->ref_cos[k]);
        const float y = biquad_cascade_step(&lp, v);
        e->mean_step[k] += y;
        e->mean_raw[k] += v;
        if (k >= k_ss) {
          e->sse += ((double)y - p->amp) * ((double)y - p->amp);
          e->sse_raw += ((double)v - p->amp) * ((double)v - p->amp);
        }
      }
      d = e->proto;
      lp = *lp0;
      for (size_t k = 0; k < n; k++) {
        const float v = demod_step(&d, d_am[k], b->ref_sin[k], b->ref_cos[k]);
        e->mean_am[k] += biquad_cascade_step(&lp, v);
      }
    }
  }
  const double m = (double)o->runs * (double)(n - k_ss);
  for (size_t i = 0; i < N_ENTRIES; i++) {
    entry_t *e = &ent[i];
    for (size_t k = 0; k < n; k++) {
      e->mean_step[k] /= o->runs;
      e->mean_am[k] /= o->runs;
      e->mean_raw[k] /= o->runs;
    }
    e->mse_db = 10.0 * log10(e->sse / m);
    e->mse_raw_db = 10.0 * log10(e->sse_raw / m);
    e->settle_s = settle_time_s(e->mean_step, n, p->amp, p->settle_band, p->fs_hz);
    e->settle_raw_s = settle_time_s(e->mean_raw, n, p->amp, p->settle_band, p->fs_hz);
    double amp, ph;
    fit_tone(e->mean_am, k_ss, n, p->am_hz, p->fs_hz, &amp, &ph);
    e->gain = amp / p->amp;
    /* a chain of low-passes lags: report the phase in (-360, 0] */
    while (ph > 0.0) {
      ph -= 360.0;
    }
    while (ph <= -360.0) {
      ph += 360.0;
    }
    e->phase_deg = ph;
  }
  free(noise);
  free(d_step);
  free(d_am);
  free(sig_step);
  free(sig_am);
}

static void print_table(const protocol_t *p, const opts_t *o, const entry_t *ent, size_t n)
{
  printf("demodulator comparison (thesis 5.4.3): fs %.0f Hz, carrier %.0f Hz, A %.3g, "
         "sigma %.3g, %d runs, output filter Butterworth %u / %.0f Hz\n",
         p->fs_hz, p->fc_hz, p->amp, p->sigma, o->runs, p->out_order, p->out_fc_hz);
  printf("MSE over t = %.3f..%.3f s; bandwidth of the demodulator alone; gain/phase at "
         "%.0f Hz after the output filter\n\n",
         p->t_ss_s, p->t_run_s, p->am_hz);
  printf("%-16s %-5s %-12s %10s %9s %11s %10s %10s %8s %11s\n", "set", "demod", "param",
         "bw-3dB[Hz]", "MSE[dB]", "MSEraw[dB]", "settle[ms]", "s.raw[ms]", "gain100",
         "phase100[d]");
  for (size_t i = 0; i < N_ENTRIES; i++) {
    const entry_t *e = &ent[i];
    char param[32], bw[32];
    if (e->proto.kind == DK_MULT && e->proto.param == 0.0) {
      snprintf(param, sizeof param, "no own LP");
    } else if (e->proto.kind == DK_MULT) {
      snprintf(param, sizeof param, "fc=%.1f Hz", e->proto.param);
    } else if (e->proto.kind == DK_KFD) {
      snprintf(param, sizeof param, "R=%.4g", e->proto.param);
    } else if (e->proto.kind == DK_RLSD) {
      snprintf(param, sizeof param, "lam=%.5f", e->proto.param);
    } else {
      snprintf(param, sizeof param, "mu=%.5f", e->proto.param);
    }
    if (isfinite(e->bw_hz)) {
      snprintf(bw, sizeof bw, "%.1f", e->bw_hz);
    } else {
      snprintf(bw, sizeof bw, "none<fc/2");
    }
    char raw[32];
    if (e->settle_raw_s * p->fs_hz >= (double)(n - 1)) {
      snprintf(raw, sizeof raw, "never"); /* the bare product's 2 wc ripple */
    } else {
      snprintf(raw, sizeof raw, "%.2f", 1e3 * e->settle_raw_s);
    }
    printf("%-16s %-5s %-12s %10s %9.2f %11.2f %10.2f %10s %8.4f %11.1f\n", e->set,
           demod_name(e->proto.kind), param, bw, e->mse_db, e->mse_raw_db, 1e3 * e->settle_s,
           raw, e->gain, e->phase_deg);
  }
  printf("\nMSEraw, s.raw: the demodulator output before the common output filter.\n");
}

static int write_json(const char *path, const protocol_t *p, const opts_t *o, double bw_target,
                      const entry_t *ent)
{
  cJSON *root = cJSON_CreateObject();
  cJSON *pr = cJSON_AddObjectToObject(root, "protocol");
  cJSON_AddNumberToObject(pr, "fs_hz", p->fs_hz);
  cJSON_AddNumberToObject(pr, "carrier_hz", p->fc_hz);
  cJSON_AddNumberToObject(pr, "amplitude", p->amp);
  cJSON_AddNumberToObject(pr, "noise_sigma", p->sigma);
  cJSON_AddNumberToObject(pr, "am_hz", p->am_hz);
  cJSON_AddNumberToObject(pr, "runs", o->runs);
  cJSON_AddNumberToObject(pr, "seed", (double)o->seed);
  cJSON_AddNumberToObject(pr, "output_filter_order", p->out_order);
  cJSON_AddNumberToObject(pr, "output_filter_cutoff_hz", p->out_fc_hz);
  cJSON_AddNumberToObject(pr, "mse_window_start_s", p->t_ss_s);
  cJSON_AddNumberToObject(pr, "mse_window_end_s", p->t_run_s);
  cJSON_AddNumberToObject(pr, "settle_band", p->settle_band);
  cJSON_AddNumberToObject(pr, "kfd_q", DEMOD_KFD_Q);
  cJSON_AddNumberToObject(pr, "mult_lowpass_order", DEMOD_MULT_LP_ORDER);
  cJSON_AddNumberToObject(pr, "bw_target_hz", bw_target);
  cJSON *pm = cJSON_AddObjectToObject(pr, "param");
  cJSON_AddStringToObject(pm, "lmsd", "mu");
  cJSON_AddStringToObject(pm, "rlsd", "lambda");
  cJSON_AddStringToObject(pm, "kfd", "R (Q = kfd_q I)");
  cJSON_AddStringToObject(pm, "mult", "cut-off (Hz) of its own Butterworth low-pass; 0 = none");
  cJSON_AddStringToObject(pr, "bw_method",
                          "bw_3db_hz: the demodulator alone, AM-tone lock-in gain, -3 dB by "
                          "bisection; null = no band limit below carrier/2");
  cJSON_AddStringToObject(pr, "measured_after_output_filter",
                          "mse_db, settle_s, gain_100hz, phase_100hz_deg; settling and "
                          "gain/phase on the mean over realisations");
  cJSON *res = cJSON_AddArrayToObject(root, "results");
  for (size_t i = 0; i < N_ENTRIES; i++) {
    const entry_t *e = &ent[i];
    cJSON *r = cJSON_CreateObject();
    cJSON_AddStringToObject(r, "demodulator", demod_name(e->proto.kind));
    cJSON_AddStringToObject(r, "set", e->set);
    cJSON_AddNumberToObject(r, "param", e->proto.param);
    cJSON_AddNumberToObject(r, "mse_db", e->mse_db);
    cJSON_AddNumberToObject(r, "settle_s", e->settle_s);
    cJSON_AddNumberToObject(r, "gain_100hz", e->gain);
    cJSON_AddNumberToObject(r, "phase_100hz_deg", e->phase_deg);
    if (isfinite(e->bw_hz)) {
      cJSON_AddNumberToObject(r, "bw_3db_hz", e->bw_hz);
    } else {
      cJSON_AddNullToObject(r, "bw_3db_hz");
    }
    cJSON_AddItemToArray(res, r);
  }
  char *text = cJSON_Print(root);
  cJSON_Delete(root);
  FILE *f = fopen(path, "w");
  int rc = -1;
  if (text != NULL && f != NULL) {
    rc = (fputs(text, f) >= 0 && fputc('\n', f) != EOF) ? 0 : -1;
  }
  if (f != NULL && fclose(f) != 0) {
    rc = -1;
  }
  free(text);
  if (rc != 0) {
    fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
  }
  return rc;
}

static int write_csv(const char *path, const protocol_t *p, const entry_t *ent, size_t n)
{
  FILE *f = fopen(path, "w");
  if (f == NULL) {
    fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
    return -1;
  }
  fprintf(f, "t_s");
  for (size_t i = 0; i < N_ENTRIES; i++) {
    fprintf(f, ",step_%s_%s", ent[i].set, demod_name(ent[i].proto.kind));
  }
  for (size_t i = 0; i < N_ENTRIES; i++) {
    fprintf(f, ",am_%s_%s", ent[i].set, demod_name(ent[i].proto.kind));
  }
  for (size_t i = 0; i < N_ENTRIES; i++) {
    fprintf(f, ",raw_%s_%s", ent[i].set, demod_name(ent[i].proto.kind));
  }
  fprintf(f, "\n");
  for (size_t k = 0; k < n; k++) {
    fprintf(f, "%.6f", (double)k / p->fs_hz);
    for (size_t i = 0; i < N_ENTRIES; i++) {
      fprintf(f, ",%.8g", ent[i].mean_step[k]);
    }
    for (size_t i = 0; i < N_ENTRIES; i++) {
      fprintf(f, ",%.8g", ent[i].mean_am[k]);
    }
    for (size_t i = 0; i < N_ENTRIES; i++) {
      fprintf(f, ",%.8g", ent[i].mean_raw[k]);
    }
    fprintf(f, "\n");
  }
  if (fclose(f) != 0) {
    fprintf(stderr, "cannot write %s\n", path);
    return -1;
  }
  return 0;
}

/* python3 plot.py JSON CSV PNG, without a shell. */
static int run_plot(const char *json, const char *csv, const char *png)
{
  const char *py = getenv("PYTHON");
  const char *args[] = {py ? py : "python3", DEMOD_COMPARE_PLOT_PY, json, csv, png};
  enum { N_ARGS = sizeof args / sizeof args[0] };
  char *argv[N_ARGS + 1];
  int rc = 0;
  for (size_t i = 0; i < N_ARGS; i++) { /* posix_spawn wants mutable strings */
    argv[i] = strdup(args[i]);
    rc |= (argv[i] == NULL);
  }
  argv[N_ARGS] = NULL;
  pid_t pid;
  int status = 0;
  if (rc != 0 || posix_spawnp(&pid, argv[0], NULL, NULL, argv, environ) != 0) {
    fprintf(stderr, "cannot run %s\n", args[0]);
    rc = -1;
  } else if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    fprintf(stderr, "plot.py failed\n");
    rc = -1;
  }
  for (size_t i = 0; i < N_ARGS; i++) {
    free(argv[i]);
  }
  return rc;
}

static char *with_suffix(const char *path, const char *suffix)
{
  const size_t n = strlen(path) + strlen(suffix) + 1;
  char *s = malloc(n);
  if (s != NULL) {
    snprintf(s, n, "%s%s", path, suffix);
  }
  return s;
}

int main(int argc, char **argv)
{
  opts_t o;
  if (parse_args(argc, argv, &o) != 0) {
    usage(argv[0]);
    return 2;
  }
  protocol_t p = {.fs_hz = 50000.0,
                  .fc_hz = 1750.0,
                  .amp = 0.01,
                  .sigma = 0.002,
                  .am_hz = 100.0,
                  .out_fc_hz = 100.0,
                  .out_order = 4u,
                  .settle_band = 0.02};

  /* References from the firmware NCO, long enough for every measurement. */
  const size_t n_ref = (size_t)(fmax(MEAS_REF_S, 0.5) * p.fs_hz);
  float *rs = malloc(n_ref * sizeof *rs), *rc = malloc(n_ref * sizeof *rc);
  double *carrier = malloc(n_ref * sizeof *carrier);
  if (!rs || !rc || !carrier || refs_fill(rs, rc, n_ref, p.fc_hz, p.fs_hz) != 0) {
    fprintf(stderr, "cannot build the references\n");
    return 1;
  }
  for (size_t k = 0; k < n_ref; k++) {
    carrier[k] = sin(2.0 * k_pi * p.fc_hz / p.fs_hz * (double)k);
  }
  const bench_t b = {p.fs_hz, p.fc_hz, rs, rc, carrier, n_ref};
  biquad_cascade_t lp0;
  if (output_filter(&p, &lp0) != 0) {
    fprintf(stderr, "cannot design the output filter\n");
    return 1;
  }

  /* Thesis set, and the bandwidths the parameters really give. */
  entry_t ent[N_ENTRIES];
  memset(ent, 0, sizeof ent);
  for (int k = 0; k < DK_COUNT; k++) {
    entry_t *e = &ent[k];
    e->set = "thesis";
    if (demod_setup(&e->proto, (demod_kind_t)k, k_thesis_param[k], p.fs_hz) != 0) {
      fprintf(stderr, "bad thesis parameter for %s\n", demod_name((demod_kind_t)k));
      return 1;
    }
    e->bw_hz = meas_bw_hz(&b, (demod_kind_t)k, k_thesis_param[k]);
  }
  const double target = (o.bw_target_hz > 0.0) ? o.bw_target_hz : ent[DK_LMSD].bw_hz;
  /* Equal-bandwidth set: every parameter tuned to the same measured bandwidth. */
  for (int k = 0; k < DK_COUNT; k++) {
    entry_t *e = &ent[DK_COUNT + k];
    e->set = "equal_bandwidth";
    const double param = meas_tune(&b, (demod_kind_t)k, target, &e->bw_hz);
    if (isnan(param) || demod_setup(&e->proto, (demod_kind_t)k, param, p.fs_hz) != 0) {
      fprintf(stderr, "cannot tune %s to %.1f Hz\n", demod_name((demod_kind_t)k), target);
      return 1;
    }
  }

  /* MSE window: after every chain has settled (twice the slowest noise-free settling,
   * at least 50 ms), then 0.1 s = 10 periods of the AM tone. */
  double slowest = 0.0;
  const size_t n_probe = (size_t)(0.5 * p.fs_hz);
  for (size_t i = 0; i < N_ENTRIES; i++) {
    slowest = fmax(slowest, noise_free_settle(&p, &b, &ent[i], &lp0, n_probe));
  }
  p.t_ss_s = fmax(0.05, ceil(2.0 * slowest / 0.01) * 0.01);
  p.t_run_s = p.t_ss_s + 0.1;
  const size_t n = (size_t)llround(p.t_run_s * p.fs_hz);
  if (n > n_ref) {
    fprintf(stderr, "settling too slow for the references (%.3f s)\n", slowest);
    return 1;
  }
  for (size_t i = 0; i < N_ENTRIES; i++) {
    ent[i].mean_step = calloc(n, sizeof(double));
    ent[i].mean_am = calloc(n, sizeof(double));
    ent[i].mean_raw = calloc(n, sizeof(double));
    if (!ent[i].mean_step || !ent[i].mean_am || !ent[i].mean_raw) {
      fprintf(stderr, "out of memory\n");
      return 1;
    }
  }
  monte_carlo(&p, &o, &b, &lp0, ent, n);
  print_table(&p, &o, ent, n);

  int rc_out = 0;
  char *json_png = NULL, *csv_png = NULL;
  const char *json = o.json, *csv = o.csv;
  if (o.png != NULL) {
    if (json == NULL) {
      json = json_png = with_suffix(o.png, ".json");
    }
    if (csv == NULL) {
      csv = csv_png = with_suffix(o.png, ".csv");
    }
    if (json == NULL || csv == NULL) {
      return 1;
    }
  }
  if (json != NULL && write_json(json, &p, &o, target, ent) != 0) {
    rc_out = 1;
  }
  if (csv != NULL && write_csv(csv, &p, ent, n) != 0) {
    rc_out = 1;
  }
  if (rc_out == 0 && o.png != NULL && run_plot(json, csv, o.png) != 0) {
    rc_out = 1;
  }
  free(json_png);
  free(csv_png);
  for (size_t i = 0; i < N_ENTRIES; i++) {
    free(ent[i].mean_step);
    free(ent[i].mean_am);
    free(ent[i].mean_raw);
  }
  free(rs);
  free(rc);
  free(carrier);
  return rc_out;
}
