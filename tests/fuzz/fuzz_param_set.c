/* The parameter-set reader (host_sim/paramset/param_set.h) fed arbitrary text. A refused
 * text leaves the values exactly as they were and says why; an accepted one gives values
 * that each pass param_check and design together, and the writer's text of them reads
 * back to the same values bit for bit. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_check.h"
#include "gyro/gyro_design.h"
#include "paramset/param_set.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  char *text = malloc(size + 1u);
  FUZZ_CHECK(text != NULL);
  memcpy(text, data, size);
  text[size] = '\0';
  param_values_t v, before;
  param_values_defaults(&v);
  before = v;
  char err[400] = "";
  param_set_meta_t m;
  const int rc = param_set_parse(text, &v, &m, err, sizeof err);
  free(text);
  if (rc != 0) {
    FUZZ_CHECK(rc == -1 && err[0] != '\0');
    FUZZ_CHECK(memcmp(&v, &before, sizeof v) == 0);
    return 0;
  }
  FUZZ_CHECK(m.format_version == PARAM_SET_FORMAT_VERSION && m.count <= (unsigned)PARAM_COUNT);
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    FUZZ_CHECK(param_check((param_idx_t)i, param_get(&v, (param_idx_t)i)) == PARAM_OK);
  }
  gyro_design_t *d = malloc(sizeof *d);
  FUZZ_CHECK(d != NULL);
  FUZZ_CHECK(gyro_design(&v, d) == GYRO_DESIGN_OK);
  free(d);
  char *out = param_set_format(&v, NULL, err, sizeof err);
  FUZZ_CHECK(out != NULL);
  param_values_t back = before;
  FUZZ_CHECK(param_set_parse(out, &back, NULL, err, sizeof err) == 0);
  free(out);
  FUZZ_CHECK(memcmp(&back, &v, sizeof v) == 0);
  return 0;
}
