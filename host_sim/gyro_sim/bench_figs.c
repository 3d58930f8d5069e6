#include "bench_figs.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BENCH_JSON_MAX_BYTES (4u << 20)

static int fail(char *err, size_t len, const char *path, const char *why)
{
  snprintf(err, len, "--isr-figures %s: %s", path, why);
  return -1;
}

/* A positive, finite number at root.a.b (.c); NULL-safe. */
static int number_at(const cJSON *root, const char *a, const char *b, const char *c, double *v)
{
  const cJSON *n = cJSON_GetObjectItemCaseSensitive(root, a);
  n = cJSON_GetObjectItemCaseSensitive(n, b);
  if (c != NULL) n = cJSON_GetObjectItemCaseSensitive(n, c);
  if (!cJSON_IsNumber(n) || !isfinite(n->valuedouble) || !(n->valuedouble > 0.0) ||
      n->valuedouble > 1e6) {
    return -1;
  }
  *v = n->valuedouble;
  return 0;
}

int bench_figs_load(const char *path, bench_figs_t *out, char *err, size_t err_len)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) return fail(err, err_len, path, strerror(errno));
  char *buf = malloc(BENCH_JSON_MAX_BYTES + 1u);
  if (buf == NULL) {
    fclose(f);
    return fail(err, err_len, path, "out of memory");
  }
  const size_t n = fread(buf, 1, BENCH_JSON_MAX_BYTES + 1u, f);
  const int read_err = ferror(f);
  fclose(f);
  if (read_err || n > BENCH_JSON_MAX_BYTES) {
    free(buf);
    return fail(err, err_len, path, read_err ? "read error" : "larger than 4 MB");
  }
  buf[n] = '\0';
  cJSON *root = cJSON_ParseWithLength(buf, n);
  free(buf);
  if (root == NULL) return fail(err, err_len, path, "not valid JSON");
  bench_figs_t t;
  memset(&t, 0, sizeof t);
  int rc = 0;
  if (number_at(root, "target", "isr_total", "mean", &t.insns_mean) != 0 ||
      number_at(root, "target", "isr_total", "max", &t.insns_max) != 0 ||
      t.insns_max < t.insns_mean) {
    rc = fail(err, err_len, path, "no target.isr_total mean/max (not a run-bench --json file?)");
  } else {
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(root, "isr_trace");
    if (tr != NULL && !cJSON_IsNull(tr)) {
      if (number_at(tr, "cycles", "flash_cold", "total_mean", &t.cycles_mean) != 0 ||
          number_at(tr, "cycles", "flash_cold", "total_max", &t.cycles_max) != 0) {
        rc = fail(err, err_len, path, "isr_trace.cycles.flash_cold is malformed");
      } else {
        t.have_cycles = 1;
      }
    }
  }
  cJSON_Delete(root);
  if (rc == 0) *out = t;
  return rc;
}
