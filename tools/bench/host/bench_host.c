/* bench_host: the benchmark cases on the host, for callgrind (tools/bench/run-bench).
 *
 *   bench_host CASE N     set the case up, then call its kernel N times inside
 *                         bench_measure(); prints "symbol=S calls=N" (S: the function
 *                         whose inclusive Ir per call is the kernel's cost)
 *   bench_host all N      every case in turn, N calls each (a smoke run)
 *   bench_host list       the case names
 * CASE is a name of bench_kernels.h (lmsd_step, ..., gyro_tick) or app_sample_isr: the
 * application's sample ISR at lock, driven by the host HAL with the bench plant.
 * Run under
 *   valgrind --tool=callgrind --collect-atstart=no --toggle-collect=bench_measure ...
 * so that only the measured calls are counted. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/app.h"
#include "bench_kernels.h"
#include "bench_plant.h"
#include "hal_host.h"
#include "hal/hal_sample_timer.h"

#define HOST_FS_HZ 50000u
#define HOST_WARMUP_MAX 400000u
#define HOST_SETTLE 5000u

typedef struct {
  bench_plant_t plant;
  app_t *app;
} host_plant_t;

static app_t s_app;
static host_plant_t s_hp;

static void plant_step(void *ctx, const hal_dac_frame_t *dac, hal_adc_frame_t *adc)
{
  host_plant_t *hp = ctx;
  (void)dac;
  bench_plant_frame(&hp->plant, &hp->app->gyro, adc);
}

static int app_setup(void)
{
  if (app_init(&s_app) != 0) return -1;
  param_values_t v;
  param_values_defaults(&v);
  s_hp.app = &s_app;
  if (bench_plant_init(&s_hp.plant, (const gyro_design_t *)s_app.applied, &v) != 0) return -2;
  if (hal_sample_timer_start(HOST_FS_HZ, app_sample_isr, &s_app) != 0) return -3;
  hal_host_attach(plant_step, &s_hp);
  gyro_start(&s_app.gyro);
  uint32_t settled = 0u;
  for (uint32_t i = 0u; i < HOST_WARMUP_MAX && settled < HOST_SETTLE; i++) {
    (void)hal_host_run(1u);
    settled = s_app.gyro.sup.mode == GYRO_MODE_LOCKED ? settled + 1u : 0u;
  }
  return settled >= HOST_SETTLE ? 0 : -4;
}

/* The callgrind window: nothing but the measured calls (and their loop). */
__attribute__((noinline)) static int bench_measure(int id, uint32_t n)
{
  if (id < 0) return hal_host_run(n) == n ? 0 : -1;
  return bk_run_kernel_only((bk_id_t)id, n);
}

static int find_case(const char *name)
{
  if (strcmp(name, "app_sample_isr") == 0) return -1;
  for (int i = 0; i < (int)BK_COUNT; i++) {
    if (strcmp(name, bk_name((bk_id_t)i)) == 0) return i;
  }
  return -2;
}

static int run_one(const char *name, uint32_t n)
{
  const int id = find_case(name);
  if (id == -2) {
    fprintf(stderr, "bench_host: unknown case %s\n", name);
    return 2;
  }
  int rc = id < 0 ? app_setup() : bk_prepare((bk_id_t)id);
  if (rc != 0) {
    fprintf(stderr, "bench_host: set-up of %s failed (%d)\n", name, rc);
    return 1;
  }
  rc = bench_measure(id, n);
  if (rc != 0) {
    fprintf(stderr, "bench_host: %s failed (%d)\n", name, rc);
    return 1;
  }
  const int locked = id < 0 ? s_app.gyro.sup.mode == GYRO_MODE_LOCKED
                            : (id == (int)BK_GYRO_TICK ? (int)bk_gyro_locked() : 1);
  printf("case=%s symbol=%s calls=%u locked=%d\n", name,
         id < 0 ? "app_sample_isr" : bk_symbol((bk_id_t)id), (unsigned)n, locked);
  return 0;
}

int main(int argc, char **argv)
{
  if (argc == 2 && strcmp(argv[1], "list") == 0) {
    for (int i = 0; i < (int)BK_COUNT; i++) printf("%s\n", bk_name((bk_id_t)i));
    printf("app_sample_isr\n");
    return 0;
  }
  if (argc != 3) {
    fprintf(stderr, "usage: bench_host CASE|all N | bench_host list\n");
    return 2;
  }
  const long n = strtol(argv[2], NULL, 10);
  if (n <= 0 || n > 100000000L) {
    fprintf(stderr, "bench_host: N must be 1..1e8\n");
    return 2;
  }
  const int rc = bk_setup();
  if (rc != 0) {
    fprintf(stderr, "bench_host: bk_setup failed (%d)\n", rc);
    return 1;
  }
  if (strcmp(argv[1], "all") != 0) return run_one(argv[1], (uint32_t)n);
  for (int i = 0; i < (int)BK_COUNT; i++) {
    const int e = run_one(bk_name((bk_id_t)i), (uint32_t)n);
    if (e != 0) return e;
  }
  return run_one("app_sample_isr", (uint32_t)n);
}
