/* Firmware parameter sets (param_set.h, docs/param-set.md): the JSON reader and writer. */
#include "paramset/param_set.h"

#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gyro/gyro_design.h"
#include "params/crc32.h"
#include "params/fw_version.h"

/* From here on a double rounds to float32 infinity: 2^128 - 2^103, half an ulp above
 * FLT_MAX (so "3.40282347e38", the nine-digit FLT_MAX, is a float). */
#define PS_F32_LIMIT 0x1.ffffffp127

/* One checked entry of "params". */
typedef struct {
  param_idx_t idx;
  param_value_t val;
} ps_entry_t;

static int fail(char *err, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(char *err, size_t len, const char *fmt, ...)
{
  if (err != NULL && len > 0u) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
  }
  return -1;
}

void param_set_crc_line(uint16_t id, uint32_t bits, char out[16])
{
  snprintf(out, 16, "%04x %08x\n", (unsigned)id, (unsigned)bits);
}

static uint32_t crc_add(uint32_t crc, param_idx_t idx, param_value_t val)
{
  char line[16];
  param_set_crc_line(param_info(idx)->id, val.u, line);
  return crc32_update(crc, line, strlen(line));
}

/* "0x" and exactly `digits` hex digits (either case) into *out. */
static bool parse_hex(const char *s, unsigned digits, uint32_t *out)
{
  if (s == NULL || s[0] != '0' || (s[1] != 'x' && s[1] != 'X') || strlen(s) != 2u + digits) {
    return false;
  }
  uint32_t v = 0u;
  for (unsigned i = 0; i < digits; i++) {
    const char c = s[2u + i];
    uint32_t d;
    if (c >= '0' && c <= '9') d = (uint32_t)(c - '0');
    else if (c >= 'a' && c <= 'f') d = (uint32_t)(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F') d = (uint32_t)(c - 'A' + 10);
    else return false;
    v = (v << 4) | d;
  }
  *out = v;
  return true;
}

/* The allowed range of parameter pi, as text: "[lo, hi] unit" or "one of 0, 1". */
static void range_text(const param_info_t *pi, char *out, size_t n)
{
  if (pi->type == PARAM_T_F32) {
    snprintf(out, n, "[%g, %g] %s", (double)pi->min.f, (double)pi->max.f, pi->unit);
  } else if (pi->type == PARAM_T_U32) {
    snprintf(out, n, "[%u, %u] %s", (unsigned)pi->min.u, (unsigned)pi->max.u, pi->unit);
  } else {
    size_t k = (size_t)snprintf(out, n, "one of");
    for (unsigned c = 0; c < 32u && k < n; c++) {
      if ((pi->choices & (1u << c)) != 0u) {
        k += (size_t)snprintf(out + k, n - k, "%s %u", (k > 6u) ? "," : "", c);
      }
    }
  }
}

/* The value of entry `where` for parameter idx: a JSON number of the parameter's kind
 * that passes param_check. */
static int parse_value(const cJSON *j, param_idx_t idx, const char *where, param_value_t *out,
                       char *err, size_t len)
{
  const param_info_t *pi = param_info(idx);
  char rng[96];
  range_text(pi, rng, sizeof rng);
  if (!cJSON_IsNumber(j)) return fail(err, len, "%s: value: expected a number", where);
  const double d = j->valuedouble;
  if (!isfinite(d)) return fail(err, len, "%s: value: not a finite number", where);
  param_value_t val;
  if (pi->type == PARAM_T_F32) {
    if (fabs(d) >= PS_F32_LIMIT) {
      return fail(err, len, "%s: value %g is out of range %s", where, d, rng);
    }
    val.f = (float)d;
  } else {
    if (d != floor(d)) return fail(err, len, "%s: value %.17g is not an integer", where, d);
    if (d < 0.0 || d > 4294967295.0) {
      return fail(err, len, "%s: value %.17g is out of range %s", where, d, rng);
    }
    val.u = (uint32_t)d;
  }
  const param_status_t st = param_check(idx, val);
  if (st != PARAM_OK) {
    return fail(err, len, "%s: value %.9g is %s: %s", where,
                pi->type == PARAM_T_F32 ? (double)val.f : (double)val.u, param_status_str(st),
                rng);
  }
  *out = val;
  return 0;
}

/* Every key of object o is one of keys[0..n), none twice, and each of them is there. */
static int check_keys(const cJSON *o, const char *where, const char *const *keys, size_t n,
                      size_t n_required, char *err, size_t len)
{
  unsigned seen = 0u;
  const cJSON *it;
  cJSON_ArrayForEach(it, o)
  {
    size_t k = 0;
    while (k < n && strcmp(it->string, keys[k]) != 0) k++;
    if (k == n) return fail(err, len, "%s: unknown key \"%s\"", where, it->string);
    if ((seen & (1u << k)) != 0u) {
      return fail(err, len, "%s: key \"%s\" given twice", where, it->string);
    }
    seen |= 1u << k;
  }
  for (size_t k = 0; k < n_required; k++) {
    if ((seen & (1u << k)) == 0u) return fail(err, len, "%s: \"%s\" missing", where, keys[k]);
  }
  return 0;
}

/* params[k]: {"id", "name", "value"} of a known, persistent, writable parameter not seen
 * before. */
static int parse_entry(const cJSON *e, int k, bool *seen, ps_entry_t *out, char *err, size_t len)
{
  static const char *const keys[] = {"id", "name", "value"};
  char where[128];
  snprintf(where, sizeof where, "params[%d]", k);
  if (!cJSON_IsObject(e))
    return fail(err, len, "%s: expected an object {id, name, value}", where);
  if (check_keys(e, where, keys, 3u, 3u, err, len) != 0) return -1;
  const cJSON *jid = cJSON_GetObjectItemCaseSensitive(e, "id");
  uint32_t id = 0u;
  if (!cJSON_IsString(jid) || !parse_hex(jid->valuestring, 4u, &id)) {
    return fail(err, len, "%s: id: expected a 16-bit id as a string \"0x%%04x\"", where);
  }
  const param_idx_t idx = param_lookup_id((uint16_t)id);
  const param_info_t *pi = param_info(idx);
  if (pi == NULL) return fail(err, len, "%s: unknown id 0x%04x in this firmware", where, id);
  snprintf(where, sizeof where, "params[%d] (id 0x%04x, %s)", k, id, pi->name);
  const cJSON *jn = cJSON_GetObjectItemCaseSensitive(e, "name");
  if (!cJSON_IsString(jn)) return fail(err, len, "%s: name: expected a string", where);
  if (strcmp(jn->valuestring, pi->name) != 0) {
    return fail(err, len, "%s: name \"%.60s\" does not match the id's name in this firmware",
                where, jn->valuestring);
  }
  if ((pi->flags & PF_READONLY) != 0u) {
    return fail(err, len, "%s: read-only: not a value of a parameter set", where);
  }
  if ((pi->flags & PF_PERSIST) == 0u) {
    return fail(err, len, "%s: not persistent (flash does not hold it)", where);
  }
  if (seen[idx]) return fail(err, len, "%s: the id appears more than once", where);
  seen[idx] = true;
  out->idx = idx;
  return parse_value(cJSON_GetObjectItemCaseSensitive(e, "value"), idx, where, &out->val, err,
                     len);
}

/* The top level's own fields: format, versions, firmware (meta is free-form). */
static int parse_header(const cJSON *root, param_set_meta_t *m, char *err, size_t len)
{
  static const char *const keys[] = {"format",         "format_version", "params", "crc32",
                                     "layout_version", "firmware",       "meta"};
  if (!cJSON_IsObject(root)) return fail(err, len, "top level: expected an object");
  if (check_keys(root, "top level", keys, 7u, 4u, err, len) != 0) return -1;
  const cJSON *f = cJSON_GetObjectItemCaseSensitive(root, "format");
  if (!cJSON_IsString(f) || strcmp(f->valuestring, PARAM_SET_FORMAT) != 0) {
    return fail(err, len, "format: expected \"%s\" (not a parameter set)", PARAM_SET_FORMAT);
  }
  const cJSON *fv = cJSON_GetObjectItemCaseSensitive(root, "format_version");
  if (!cJSON_IsNumber(fv) || fv->valuedouble != (double)PARAM_SET_FORMAT_VERSION) {
    if (cJSON_IsNumber(fv) && fv->valuedouble > (double)PARAM_SET_FORMAT_VERSION) {
      return fail(err, len, "format_version %g is newer than this reader's (%u)",
                  fv->valuedouble, PARAM_SET_FORMAT_VERSION);
    }
    return fail(err, len, "format_version: expected %u", PARAM_SET_FORMAT_VERSION);
  }
  m->format_version = PARAM_SET_FORMAT_VERSION;
  const cJSON *lv = cJSON_GetObjectItemCaseSensitive(root, "layout_version");
  m->layout_version = -1;
  if (lv != NULL) {
    if (!cJSON_IsNumber(lv) || lv->valuedouble < 0.0 || lv->valuedouble > 65535.0 ||
        lv->valuedouble != floor(lv->valuedouble)) {
      return fail(err, len, "layout_version: expected an integer in [0, 65535]");
    }
    m->layout_version = (long)lv->valuedouble;
  }
  const cJSON *fw = cJSON_GetObjectItemCaseSensitive(root, "firmware");
  m->firmware[0] = '\0';
  if (fw != NULL) {
    if (!cJSON_IsString(fw)) return fail(err, len, "firmware: expected a string");
    snprintf(m->firmware, sizeof m->firmware, "%s", fw->valuestring);
  }
  const cJSON *meta = cJSON_GetObjectItemCaseSensitive(root, "meta");
  if (meta != NULL && !cJSON_IsObject(meta)) return fail(err, len, "meta: expected an object");
  return 0;
}

/* Every entry checked, the checksum compared, then the whole set designed, onto a copy
 * of *v. Returns 0 with *v the new values, or -1. */
static int apply_entries(const cJSON *root, param_values_t *v, unsigned *count, char *err,
                         size_t len)
{
  const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "params");
  if (!cJSON_IsArray(arr)) return fail(err, len, "params: expected a list of entries");
  bool seen[PARAM_COUNT] = {false};
  param_values_t t = *v;
  uint32_t crc = 0u;
  int k = 0;
  const cJSON *e;
  cJSON_ArrayForEach(e, arr)
  {
    ps_entry_t ent = {PARAM_COUNT, {.u = 0u}};
    if (parse_entry(e, k, seen, &ent, err, len) != 0) return -1;
    crc = crc_add(crc, ent.idx, ent.val);
    param_put(&t, ent.idx, ent.val);
    k++;
  }
  const cJSON *jc = cJSON_GetObjectItemCaseSensitive(root, "crc32");
  uint32_t want = 0u;
  if (!cJSON_IsString(jc) || !parse_hex(jc->valuestring, 8u, &want)) {
    return fail(err, len, "crc32: expected a string \"0x%%08x\"");
  }
  if (want != crc) {
    return fail(err, len,
                "checksum mismatch: file edited by hand? crc32 says 0x%08x, the values give "
                "0x%08x (write sets with gyro-sim --save-params or tools/gyrotools/paramset.py)",
                (unsigned)want, (unsigned)crc);
  }
  gyro_design_t *d = malloc(sizeof *d);
  if (d == NULL) return fail(err, len, "out of memory");
  const gyro_design_status_t ds = gyro_design(&t, d);
  free(d);
  if (ds != GYRO_DESIGN_OK) {
    return fail(err, len, "the values are refused together (as a commit would be): %s",
                gyro_design_reason(ds));
  }
  *v = t;
  *count = (unsigned)k;
  return 0;
}

int param_set_parse(const char *json, param_values_t *v_inout, param_set_meta_t *meta_opt,
                    char *err, size_t err_len)
{
  if (json == NULL || v_inout == NULL) return fail(err, err_len, "no text or no values");
  const char *end = NULL;
  cJSON *root = cJSON_ParseWithOpts(json, &end, 1);
  if (root == NULL) {
    const char *at = (end != NULL) ? end : cJSON_GetErrorPtr();
    return fail(err, err_len, "not valid JSON near '%.20s'", at != NULL ? at : "");
  }
  param_set_meta_t m;
  memset(&m, 0, sizeof m);
  int rc = parse_header(root, &m, err, err_len);
  if (rc == 0) rc = apply_entries(root, v_inout, &m.count, err, err_len);
  cJSON_Delete(root);
  if (rc == 0 && meta_opt != NULL) *meta_opt = m;
  return rc;
}

/* The whole file into a NUL-terminated buffer (malloc'd), or NULL with err. */
static char *read_text(const char *path, char *err, size_t len)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    fail(err, len, "%s: %s", path, strerror(errno));
    return NULL;
  }
  char *buf = malloc(PARAM_SET_FILE_MAX + 1u);
  size_t n = 0;
  if (buf != NULL) n = fread(buf, 1, PARAM_SET_FILE_MAX + 1u, f);
  const int bad = buf == NULL || ferror(f);
  fclose(f);
  const char *why = NULL;
  if (buf == NULL) why = "out of memory";
  else if (bad) why = "read error";
  else if (n > PARAM_SET_FILE_MAX) why = "larger than 1 MiB";
  else if (memchr(buf, '\0', n) != NULL) why = "contains a NUL byte";
  if (why != NULL) {
    fail(err, len, "%s: %s", path, why);
    free(buf);
    return NULL;
  }
  buf[n] = '\0';
  return buf;
}

int param_set_load_file(const char *path, param_values_t *v_inout, param_set_meta_t *meta_opt,
                        char *err, size_t err_len)
{
  char *buf = read_text(path, err, err_len);
  if (buf == NULL) return -1;
  char inner[400];
  const int rc = param_set_parse(buf, v_inout, meta_opt, inner, sizeof inner);
  free(buf);
  if (rc != 0) return fail(err, err_len, "%s: %s", path, inner);
  return 0;
}

/* ---- writer ---- */

typedef struct {
  char *s;
  size_t n, cap;
  bool oom;
} ps_buf_t;

static void put(ps_buf_t *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void put(ps_buf_t *b, const char *fmt, ...)
{
  for (int pass = 0; pass < 2 && !b->oom; pass++) {
    va_list ap;
    va_start(ap, fmt);
    const int w = vsnprintf(b->s + b->n, b->cap - b->n, fmt, ap);
    va_end(ap);
    if (w < 0) {
      b->oom = true;
    } else if ((size_t)w < b->cap - b->n) {
      b->n += (size_t)w;
      return;
    } else {
      const size_t cap = 2u * (b->cap + (size_t)w);
      char *g = realloc(b->s, cap);
      if (g == NULL) {
        b->oom = true;
      } else {
        b->s = g;
        b->cap = cap;
      }
    }
  }
}

/* The shortest decimal that reads back as exactly f (at most 9 significant digits), as
 * a JSON number that looks like a float: positional below 1e16 ("30.0", not "3e+01"),
 * with an exponent below 1e-4 and from 1e16 (as Python's repr). */
static void format_f32(float f, char out[40])
{
  int p = 1;
  for (; p < 9; p++) {
    snprintf(out, 40, "%.*e", p - 1, (double)f);
    const double d = strtod(out, NULL);
    const float back = fabs(d) < PS_F32_LIMIT ? (float)d : 0.0f; /* 3.403e38: no float */
    if (fabs(d) < PS_F32_LIMIT && memcmp(&back, &f, sizeof f) == 0) break;
  }
  snprintf(out, 40, "%.*e", p - 1, (double)f);
  const int x = atoi(strchr(out, 'e') + 1); /* the decimal exponent */
  snprintf(out, 40, "%.*g", (x >= p && x < 16) ? x + 1 : p, (double)f);
  if (strpbrk(out, ".e") == NULL) strcat(out, ".0");
}

/* The "params" list of every persistent writable parameter of v, and its checksum. */
static int put_entries(ps_buf_t *b, const param_values_t *v, uint32_t *crc, char *err, size_t len)
{
  const char *sep = "";
  *crc = 0u;
  put(b, "  \"params\": [");
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_idx_t idx = (param_idx_t)i;
    const param_info_t *pi = param_info(idx);
    if ((pi->flags & PF_PERSIST) == 0u || (pi->flags & PF_READONLY) != 0u) continue;
    const param_value_t x = param_get(v, idx);
    const param_status_t st = param_check(idx, x);
    if (st != PARAM_OK) return fail(err, len, "%s: %s", pi->name, param_status_str(st));
    char num[40];
    if (pi->type == PARAM_T_F32) format_f32(x.f, num);
    else snprintf(num, sizeof num, "%u", (unsigned)x.u);
    put(b, "%s\n    {\"id\": \"0x%04x\", \"name\": \"%s\", \"value\": %s}", sep,
        (unsigned)pi->id, pi->name, num);
    *crc = crc_add(*crc, idx, x);
    sep = ",";
  }
  put(b, "\n  ],\n");
  return 0;
}

char *param_set_format(const param_values_t *v, const char *meta_json, char *err, size_t err_len)
{
  char *meta = NULL;
  if (meta_json != NULL) {
    cJSON *m = cJSON_Parse(meta_json);
    if (!cJSON_IsObject(m)) {
      cJSON_Delete(m);
      fail(err, err_len, "meta: expected a JSON object");
      return NULL;
    }
    meta = cJSON_PrintUnformatted(m);
    cJSON_Delete(m);
  }
  ps_buf_t b = {malloc(4096u), 0u, 4096u, false};
  if (b.s == NULL) {
    free(meta);
    fail(err, err_len, "out of memory");
    return NULL;
  }
  put(&b, "{\n  \"format\": \"%s\",\n  \"format_version\": %u,\n", PARAM_SET_FORMAT,
      PARAM_SET_FORMAT_VERSION);
  put(&b, "  \"layout_version\": %u,\n  \"firmware\": \"%s\",\n",
      (unsigned)PARAM_LAYOUT_VERSION, fw_version_string());
  if (meta != NULL) put(&b, "  \"meta\": %s,\n", meta);
  free(meta);
  uint32_t crc = 0u;
  if (put_entries(&b, v, &crc, err, err_len) != 0) {
    free(b.s);
    return NULL;
  }
  put(&b, "  \"crc32\": \"0x%08x\"\n}\n", (unsigned)crc);
  if (b.oom) {
    free(b.s);
    fail(err, err_len, "out of memory");
    return NULL;
  }
  return b.s;
}

int param_set_write_file(const char *path, const param_values_t *v, const char *meta_json,
                         char *err, size_t err_len)
{
  char *txt = param_set_format(v, meta_json, err, err_len);
  if (txt == NULL) return -1;
  char tmp[4096];
  if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp) {
    free(txt);
    return fail(err, err_len, "%s: path too long", path);
  }
  FILE *f = fopen(tmp, "w");
  int rc = 0;
  if (f == NULL) {
    rc = fail(err, err_len, "%s: %s", path, strerror(errno));
  } else {
    const bool ok = fputs(txt, f) >= 0;
    if (fclose(f) != 0 || !ok || rename(tmp, path) != 0) {
      rc = fail(err, err_len, "%s: %s", path, strerror(errno));
      remove(tmp);
    }
  }
  free(txt);
  return rc;
}
