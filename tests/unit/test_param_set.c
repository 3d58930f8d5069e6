/* Firmware parameter sets (host_sim/paramset/param_set.h, docs/param-set.md): a complete
 * set written and parsed back bit for bit; a partial set changes only its entries; every
 * class of bad file refused with the entry named and the values left as they were (bad
 * JSON, format, version, keys, unknown id, name mismatch, duplicate, read-only and
 * non-persistent parameters, range, choice, integer, non-numbers, checksum, values that
 * cannot be designed together); the file functions. The parameters are found from the
 * table by their kind, so the tests hold for any parameter list. The checksum is
 * recomputed here with zlib's crc32, the reference the format names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <cmocka.h>
#include <zlib.h>

#include "gyro/gyro_design.h"
#include "paramset/param_set.h"

/* ---- helpers ---- */

static bool writable_persistent(const param_info_t *pi)
{
  return (pi->flags & PF_PERSIST) != 0u && (pi->flags & PF_READONLY) == 0u;
}

/* The first persistent, writable parameter of a type; PARAM_COUNT if none. */
static param_idx_t find_type(param_type_t t)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if (writable_persistent(pi) && pi->type == (uint8_t)t) return (param_idx_t)i;
  }
  return PARAM_COUNT;
}

static param_idx_t find_flags(uint8_t set, uint8_t clear)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if ((pi->flags & set) == set && (pi->flags & clear) == 0u) return (param_idx_t)i;
  }
  return PARAM_COUNT;
}

static bool designable(const param_values_t *v)
{
  gyro_design_t *d = malloc(sizeof *d);
  assert_non_null(d);
  const bool ok = gyro_design(v, d) == GYRO_DESIGN_OK;
  free(d);
  return ok;
}

/* One entry of a hand-made file: the JSON text of the value and the bits it stands for. */
typedef struct {
  uint16_t id;
  const char *name;
  char value[48];
  uint32_t bits;
} ent_t;

static ent_t ent_of(param_idx_t i, param_value_t x)
{
  const param_info_t *pi = param_info(i);
  ent_t e = {pi->id, pi->name, "", x.u};
  if (pi->type == PARAM_T_F32) snprintf(e.value, sizeof e.value, "%.9g", (double)x.f);
  else snprintf(e.value, sizeof e.value, "%u", (unsigned)x.u);
  return e;
}

static ent_t ent_text(param_idx_t i, const char *value, uint32_t bits)
{
  const param_info_t *pi = param_info(i);
  ent_t e = {pi->id, pi->name, "", bits};
  snprintf(e.value, sizeof e.value, "%s", value);
  return e;
}

/* CRC-32 (zlib) of the canonical lines of e[0..n). */
static uint32_t crc_of(const ent_t *e, int n)
{
  uLong c = crc32(0uL, Z_NULL, 0u);
  for (int k = 0; k < n; k++) {
    char line[32];
    const int w = snprintf(line, sizeof line, "%04x %08x\n", e[k].id, (unsigned)e[k].bits);
    c = crc32(c, (const Bytef *)line, (uInt)w);
  }
  return (uint32_t)c;
}

/* A format-1 file of entries e[0..n) with the right checksum; `extra` (or "") is put
 * among the top-level keys. Static buffer. */
static const char *doc(const ent_t *e, int n, const char *extra)
{
  static char buf[16384];
  size_t k = (size_t)snprintf(buf, sizeof buf,
                              "{\"format\": \"gyro-param-set\", \"format_version\": 1, %s"
                              "\"params\": [",
                              extra);
  for (int i = 0; i < n; i++) {
    k += (size_t)snprintf(buf + k, sizeof buf - k,
                          "%s{\"id\": \"0x%04x\", \"name\": \"%s\", "
                          "\"value\": %s}",
                          i ? ", " : "", e[i].id, e[i].name, e[i].value);
  }
  snprintf(buf + k, sizeof buf - k, "], \"crc32\": \"0x%08x\"}", (unsigned)crc_of(e, n));
  return buf;
}

/* The text must be refused with `want` in the message and the values untouched. */
static void refused(const char *json, const char *want)
{
  param_values_t v, before;
  param_values_defaults(&v);
  v.drive_freq_hz = 1234.5f; /* not a default: "unchanged" is not "reset" */
  before = v;
  char err[400] = "";
  param_set_meta_t m;
  assert_int_equal(param_set_parse(json, &v, &m, err, sizeof err), -1);
  if (strstr(err, want) == NULL)
    fail_msg("wanted \"%s\" in \"%s\" for %.200s", want, err, json);
  assert_memory_equal(&v, &before, sizeof v);
}

/* A value near the default but not it, with a float pattern no short decimal gives. */
static param_value_t nudge(param_idx_t idx)
{
  const param_info_t *pi = param_info(idx);
  param_value_t x = pi->def;
  if (pi->type == PARAM_T_F32) {
    const float base = x.f != 0.0f ? x.f * 1.0009765f
                                   : pi->min.f + 1e-3f * (pi->max.f - pi->min.f);
    x.f = nextafterf(base, x.f != pi->max.f ? pi->max.f : pi->min.f);
  } else if (pi->type == PARAM_T_U32) {
    x.u = x.u < pi->max.u ? x.u + 1u : x.u - 1u;
  } else {
    for (unsigned c = 0; c < 32u; c++) {
      if ((pi->choices & (1u << c)) != 0u && c != pi->def.u) x.u = c;
    }
  }
  return x;
}

/* Values off their defaults for as many writable persistent parameters as design
 * together. */
static unsigned perturbed(param_values_t *v)
{
  param_values_defaults(v);
  unsigned changed = 0u;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_idx_t idx = (param_idx_t)i;
    const param_info_t *pi = param_info(idx);
    if (!writable_persistent(pi)) continue;
    const param_value_t x = nudge(idx);
    param_values_t t = *v;
    param_put(&t, idx, x);
    if (param_check(idx, x) == PARAM_OK && designable(&t)) {
      *v = t;
      changed++;
    }
  }
  return changed;
}

/* ---- good files ---- */

static void test_round_trip_bit_exact(void **state)
{
  (void)state;
  param_values_t v;
  unsigned n_writable = 0u;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    n_writable += writable_persistent(param_info((param_idx_t)i)) ? 1u : 0u;
  }
  const unsigned changed = perturbed(&v);
  assert_true(2u * changed >= n_writable); /* most of the table is exercised */
  char err[400] = "";
  char *txt = param_set_format(&v, "{\"part\": \"SN 17\", \"notes\": [1, 2]}", err, sizeof err);
  assert_non_null(txt);
  param_values_t back;
  param_values_defaults(&back);
  param_set_meta_t m;
  assert_int_equal(param_set_parse(txt, &back, &m, err, sizeof err), 0);
  assert_memory_equal(&back, &v, sizeof v);
  assert_int_equal(m.count, n_writable); /* a complete set */
  assert_int_equal(m.format_version, 1);
  assert_int_equal(m.layout_version, (long)PARAM_LAYOUT_VERSION);
  assert_true(m.firmware[0] != '\0');
  /* applied onto other values, the complete set gives the same */
  param_values_t other = v;
  other.drive_freq_hz = 1000.0f;
  assert_int_equal(param_set_parse(txt, &other, NULL, err, sizeof err), 0);
  assert_memory_equal(&other, &v, sizeof v);
  free(txt);
}

/* Every writable persistent parameter and no other is written; a float as a short
 * decimal that reads back exactly, looking like a float ("30.0"). */
static void test_writer_text(void **state)
{
  (void)state;
  param_values_t v;
  param_values_defaults(&v);
  char err[400];
  char *txt = param_set_format(&v, NULL, err, sizeof err);
  assert_non_null(txt);
  assert_null(strstr(txt, "\"meta\""));
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    char key[96];
    snprintf(key, sizeof key, "\"name\": \"%s\", \"value\": ", pi->name);
    const char *at = strstr(txt, key);
    assert_true((at != NULL) == writable_persistent(pi));
    if (at == NULL || pi->type != PARAM_T_F32) continue;
    const char *num = at + strlen(key);
    const size_t n = strcspn(num, "}");
    char nine[40]; /* nine digits always read back; the writer's text is no longer */
    const int w = snprintf(nine, sizeof nine, "%.9g", (double)pi->def.f);
    const bool short_enough = n <= (size_t)w + 2u || (strchr(nine, 'e') != NULL && n <= 19u);
    if (!short_enough || strcspn(num, ".e") >= n) fail_msg("%s: %.*s", pi->name, (int)n, num);
    assert_true((float)strtod(num, NULL) == pi->def.f);
  }
  free(txt);
  assert_null(param_set_format(&v, "[1]", err, sizeof err));
  assert_non_null(strstr(err, "meta"));
  const param_idx_t f = find_type(PARAM_T_F32);
  param_value_t x = {.f = param_info(f)->max.f * 2.0f + 1.0f}; /* the writer checks too */
  param_put(&v, f, x);
  assert_null(param_set_format(&v, NULL, err, sizeof err));
  assert_non_null(strstr(err, param_info(f)->name));
}

static void test_partial_set(void **state)
{
  (void)state;
  const param_idx_t f = find_type(PARAM_T_F32), u = find_type(PARAM_T_U32);
  assert_true(f < PARAM_COUNT && u < PARAM_COUNT);
  const param_value_t xf = nudge(f), xu = nudge(u);
  /* file order is not table order; integers as 5.0 are integers */
  char utext[32];
  snprintf(utext, sizeof utext, "%u.0", (unsigned)xu.u);
  const ent_t e[2] = {ent_text(u, utext, xu.u), ent_of(f, xf)};
  param_values_t v, want;
  param_values_defaults(&v);
  want = v;
  param_put(&want, f, xf);
  param_put(&want, u, xu);
  char err[400] = "";
  param_set_meta_t m;
  assert_int_equal(param_set_parse(doc(e, 2,
                                       "\"layout_version\": 3, \"firmware\": \"9.9.9\", "
                                       "\"meta\": {\"anything\": [null, {}]}, "),
                                   &v, &m, err, sizeof err),
                   0);
  assert_memory_equal(&v, &want, sizeof v);
  assert_int_equal(m.count, 2);
  assert_int_equal(m.layout_version, 3);
  assert_string_equal(m.firmware, "9.9.9");
  /* an empty set changes nothing */
  assert_int_equal(param_set_parse(doc(e, 0, ""), &v, &m, err, sizeof err), 0);
  assert_memory_equal(&v, &want, sizeof v);
  assert_int_equal(m.layout_version, -1);
}

/* -0 is checksummed as written (0x80000000) and stored as +0 (param_put). */
static void test_negative_zero(void **state)
{
  (void)state;
  param_idx_t z = PARAM_COUNT;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT && z == PARAM_COUNT; i++) {
    const param_info_t *pi = param_info((param_idx_t)i);
    if (writable_persistent(pi) && pi->type == PARAM_T_F32 && pi->min.f <= 0.0f &&
        pi->max.f >= 0.0f && pi->def.f != 0.0f) {
      z = (param_idx_t)i;
    }
  }
  if (z == PARAM_COUNT) skip();
  const ent_t e = ent_text(z, "-0.0", 0x80000000u);
  param_values_t v;
  param_values_defaults(&v);
  char err[400] = "";
  const int rc = param_set_parse(doc(&e, 1, ""), &v, NULL, err, sizeof err);
  if (rc != 0 && strstr(err, "refused together") != NULL) skip(); /* 0 does not design */
  assert_int_equal(rc, 0);
  assert_int_equal(param_get(&v, z).u, 0u);
}

/* ---- bad files ---- */

static void test_bad_structure(void **state)
{
  (void)state;
  const param_idx_t f = find_type(PARAM_T_F32);
  const ent_t e = ent_of(f, param_info(f)->def);
  char ok[16384], buf[16500];
  snprintf(ok, sizeof ok, "%s", doc(&e, 1, ""));
  refused("{", "not valid JSON");
  refused("", "not valid JSON");
  snprintf(buf, sizeof buf, "%s x", ok);
  refused(buf, "not valid JSON");
  refused("[1, 2]", "top level: expected an object");
  refused("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": []}",
          "\"crc32\" missing");
  refused(doc(&e, 1, "\"colour\": 1, "), "unknown key \"colour\"");
  refused(doc(&e, 1, "\"meta\": 1, "), "meta: expected an object");
  refused(doc(&e, 1, "\"firmware\": 1, "), "firmware: expected a string");
  refused(doc(&e, 1, "\"layout_version\": -1, "), "layout_version");
  refused(doc(&e, 1, "\"format\": \"gyro-param-set\", "), "given twice");
  char *p;
  snprintf(buf, sizeof buf, "%s", ok);
  p = strstr(buf, "gyro-param-set");
  p[0] = 'G';
  refused(buf, "format: expected \"gyro-param-set\"");
  snprintf(buf, sizeof buf, "%s", ok);
  p = strstr(buf, "\"format_version\": 1");
  p[18] = '2';
  refused(buf, "format_version 2 is newer than this reader's (1)");
  p[18] = '0';
  refused(buf, "format_version: expected 1");
  refused("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": 7, "
          "\"crc32\": \"0x00000000\"}",
          "params: expected a list");
}

static void test_bad_entry(void **state)
{
  (void)state;
  const param_idx_t f = find_type(PARAM_T_F32);
  const param_info_t *pf = param_info(f);
  const ent_t good = ent_of(f, pf->def);
  uint16_t unused = 0xFFFFu;
  while (param_lookup_id(unused) != PARAM_COUNT) unused--;
  ent_t e[2] = {good, good};
  refused(doc(e, 2, ""), "the id appears more than once");
  e[0].id = unused;
  char want[64];
  snprintf(want, sizeof want, "params[0]: unknown id 0x%04x", unused);
  refused(doc(e, 1, ""), want);
  e[0] = good;
  e[0].name = "drive.no_such_name";
  refused(doc(e, 1, ""), "name \"drive.no_such_name\" does not match");
  char buf[16384];
  snprintf(buf, sizeof buf, "%s", doc(&good, 1, ""));
  char *p = strstr(buf, "\"id\": \"0x");
  p[10] = 'g'; /* not hex */
  refused(buf, "params[0]: id: expected a 16-bit id");
  snprintf(buf, sizeof buf,
           "{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [{\"id\": %u, "
           "\"name\": \"%s\", \"value\": 1}], \"crc32\": \"0x00000000\"}",
           pf->id, pf->name);
  refused(buf, "id: expected a 16-bit id as a string");
  snprintf(buf, sizeof buf,
           "{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [{\"id\": "
           "\"0x%03x\", \"name\": \"%s\", \"value\": 1}], \"crc32\": \"0x00000000\"}",
           pf->id, pf->name);
  refused(buf, "id: expected a 16-bit id"); /* exactly four digits */
  snprintf(buf, sizeof buf,
           "{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [{\"id\": "
           "\"0x%04x\", \"name\": \"%s\", \"value\": 1, \"unit\": \"V\"}], \"crc32\": \"0x0\"}",
           pf->id, pf->name);
  refused(buf, "params[0]: unknown key \"unit\"");
  refused("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [3], "
          "\"crc32\": \"0x00000000\"}",
          "params[0]: expected an object");
  refused("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [{\"id\": "
          "\"0x0101\"}], \"crc32\": \"0x00000000\"}",
          "\"name\" missing");
}

static void test_flags_refused(void **state)
{
  (void)state;
  const param_idx_t ro = find_flags(PF_READONLY, 0u);
  if (ro < PARAM_COUNT) {
    const ent_t e = ent_of(ro, param_info(ro)->def);
    refused(doc(&e, 1, ""), "read-only");
  }
  const param_idx_t np = find_flags(0u, PF_PERSIST | PF_READONLY);
  if (np < PARAM_COUNT) {
    const ent_t e = ent_of(np, param_info(np)->def);
    refused(doc(&e, 1, ""), "not persistent");
  }
  if (ro == PARAM_COUNT || np == PARAM_COUNT) {
    /* the table has none of one kind: nothing to refuse for it */
    print_message("read-only %s, non-persistent writable %s in this table\n",
                  ro < PARAM_COUNT ? "found" : "none", np < PARAM_COUNT ? "found" : "none");
  }
}

static void test_bad_values(void **state)
{
  (void)state;
  const param_idx_t f = find_type(PARAM_T_F32), u = find_type(PARAM_T_U32),
                    en = find_type(PARAM_T_ENUM);
  assert_true(f < PARAM_COUNT && u < PARAM_COUNT && en < PARAM_COUNT);
  const param_info_t *pf = param_info(f), *pu = param_info(u), *pe = param_info(en);
  char t[48];
  snprintf(t, sizeof t, "%.9g", (double)pf->max.f * 2.0 + 1.0);
  ent_t e = ent_text(f, t, 0u);
  refused(doc(&e, 1, ""), "is out of range: [");
  e = ent_text(f, "1e39", 0u); /* beyond float32 */
  refused(doc(&e, 1, ""), "out of range");
  e = ent_text(f, "1e999", 0u); /* cJSON reads inf */
  refused(doc(&e, 1, ""), "not a finite number");
  e = ent_text(f, "1e-41", 0u); /* a subnormal float32 */
  refused(doc(&e, 1, ""), "out of range");
  static const char *const not_numbers[] = {"\"nan\"", "\"1489.9\"", "null",
                                            "true",    "[1]",        "{}"};
  for (size_t k = 0; k < sizeof not_numbers / sizeof not_numbers[0]; k++) {
    e = ent_text(f, not_numbers[k], 0u);
    refused(doc(&e, 1, ""), "value: expected a number");
  }
  e = ent_text(f, "NaN", 0u); /* not JSON */
  refused(doc(&e, 1, ""), "not valid JSON");
  e = ent_text(u, "1.5", 0u);
  refused(doc(&e, 1, ""), "value 1.5 is not an integer");
  e = ent_text(u, "-1", 0u);
  refused(doc(&e, 1, ""), "out of range");
  e = ent_text(u, "4294967296", 0u);
  refused(doc(&e, 1, ""), "out of range");
  if (pu->max.u < 4294967295u) {
    snprintf(t, sizeof t, "%u", (unsigned)pu->max.u + 1u);
    e = ent_text(u, t, pu->max.u + 1u);
    refused(doc(&e, 1, ""), "out of range");
  }
  unsigned bad = 0u;
  while (bad < 32u && (pe->choices & (1u << bad)) != 0u) bad++;
  snprintf(t, sizeof t, "%u", bad);
  e = ent_text(en, t, bad);
  refused(doc(&e, 1, ""), "not an allowed choice: one of");
  e = ent_text(en, "0.5", 0u);
  refused(doc(&e, 1, ""), "not an integer");
}

static void test_checksum(void **state)
{
  (void)state;
  const param_idx_t f = find_type(PARAM_T_F32);
  param_value_t x = param_info(f)->def;
  const ent_t e = ent_of(f, x);
  char buf[16384];
  snprintf(buf, sizeof buf, "%s", doc(&e, 1, ""));
  char *c = strstr(buf, "\"crc32\": \"0x") + 12;
  *c = (*c == '0') ? '1' : '0';
  refused(buf, "checksum mismatch: file edited by hand?");
  /* a value edited by one float step: same text length, other bits */
  x.f = nextafterf(x.f, param_info(f)->max.f);
  ent_t edited = ent_of(f, x);
  edited.bits = param_info(f)->def.u; /* the checksum of the old value */
  refused(doc(&edited, 1, ""), "checksum mismatch");
  c[0] = 'z'; /* not hex */
  refused(buf, "crc32: expected a string");
  refused("{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [], "
          "\"crc32\": \"0x000000000\"}",
          "crc32: expected a string"); /* nine digits */
  snprintf(buf, sizeof buf,
           "{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [], "
           "\"crc32\": 0}");
  refused(buf, "crc32: expected a string");
  snprintf(buf, sizeof buf,
           "{\"format\": \"gyro-param-set\", \"format_version\": 1, \"params\": [], "
           "\"crc32\": \"0x00000000\"}");
  param_values_t v;
  param_values_defaults(&v);
  char err[200];
  assert_int_equal(param_set_parse(buf, &v, NULL, err, sizeof err), 0); /* CRC of nothing */
}

/* Values that pass one by one but not together are refused as a commit refuses them:
 * found from the table by setting one parameter at a time to an end of its range. */
static void test_refused_together(void **state)
{
  (void)state;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_idx_t idx = (param_idx_t)i;
    const param_info_t *pi = param_info(idx);
    if (!writable_persistent(pi)) continue;
    const param_value_t ends[2] = {pi->min, pi->max};
    for (int k = 0; k < 2; k++) {
      param_values_t v;
      param_values_defaults(&v);
      param_put(&v, idx, ends[k]);
      if (param_check(idx, ends[k]) != PARAM_OK || designable(&v)) continue;
      const ent_t e = ent_of(idx, ends[k]);
      refused(doc(&e, 1, ""), "the values are refused together (as a commit would be): ");
      return;
    }
  }
  skip(); /* every single value designs with the defaults */
}

/* ---- files ---- */

static void test_files(void **state)
{
  (void)state;
  char dir[] = "/tmp/test_param_set_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char path[128], err[400];
  snprintf(path, sizeof path, "%s/part.json", dir);
  param_values_t v, back;
  perturbed(&v);
  assert_int_equal(param_set_write_file(path, &v, "{\"part\": 1}", err, sizeof err), 0);
  param_values_defaults(&back);
  param_set_meta_t m;
  assert_int_equal(param_set_load_file(path, &back, &m, err, sizeof err), 0);
  assert_memory_equal(&back, &v, sizeof v);
  /* a file that is not there, one with a NUL byte, a folder that is not there */
  char missing[160];
  snprintf(missing, sizeof missing, "%s/none.json", dir);
  assert_int_equal(param_set_load_file(missing, &back, NULL, err, sizeof err), -1);
  assert_non_null(strstr(err, missing));
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  fwrite("{\0}", 1, 3, f);
  fclose(f);
  assert_int_equal(param_set_load_file(path, &back, NULL, err, sizeof err), -1);
  assert_non_null(strstr(err, "NUL"));
  snprintf(missing, sizeof missing, "%s/no/such/dir.json", dir);
  assert_int_equal(param_set_write_file(missing, &v, NULL, err, sizeof err), -1);
  assert_non_null(strstr(err, missing));
  /* a bad file's message starts with its path */
  f = fopen(path, "w");
  assert_non_null(f);
  fputs("{\"format\": 1}", f);
  fclose(f);
  assert_int_equal(param_set_load_file(path, &back, NULL, err, sizeof err), -1);
  assert_true(strncmp(err, path, strlen(path)) == 0);
  assert_memory_equal(&back, &v, sizeof v);
  remove(path);
  remove(dir);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_round_trip_bit_exact),
      cmocka_unit_test(test_writer_text),
      cmocka_unit_test(test_partial_set),
      cmocka_unit_test(test_negative_zero),
      cmocka_unit_test(test_bad_structure),
      cmocka_unit_test(test_bad_entry),
      cmocka_unit_test(test_flags_refused),
      cmocka_unit_test(test_bad_values),
      cmocka_unit_test(test_checksum),
      cmocka_unit_test(test_refused_together),
      cmocka_unit_test(test_files),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
