/* The interrupt's cost on the Cortex-M4F, as tools/bench/run-bench measured it, for the
 * figures of a scenario: the host simulator cannot count target instructions itself,
 * so it reports the benchmark's figures when given its JSON (--isr-figures FILE). */
#ifndef GYRO_SIM_BENCH_FIGS_H
#define GYRO_SIM_BENCH_FIGS_H

#include <stddef.h>

typedef struct {
  double insns_mean, insns_max;   /* sample ISR entry to exit, instructions per tick */
  double cycles_mean, cycles_max; /* cycle estimate, as linked (run-bench's primary) */
  int have_cycles;                /* 0 when the run had no instruction trace (--quick) */
} bench_figs_t;

/* Reads run-bench's --json output. Returns 0, or -1 with a message in err (and *out
 * untouched) for a missing, unreadable, malformed or implausible file. */
int bench_figs_load(const char *path, bench_figs_t *out, char *err, size_t err_len);

#endif /* GYRO_SIM_BENCH_FIGS_H */
