#include "params/params.h"

#include <math.h>
#include <string.h>

#define PARAM_VAL_F32(x) \
  { \
    .f = (x) \
  }
#define PARAM_VAL_U32(x) \
  { \
    .u = (x) \
  }
#define PARAM_VAL_ENUM(x) \
  { \
    .u = (x) \
  }

static const param_info_t k_param_table[PARAM_COUNT] = {
#define PARAM_X_INFO(sym, id_, name_, type_, unit_, min_, max_, def_, choices_, flags_, help_) \
  {.name = (name_), \
   .unit = (unit_), \
   .help = (help_), \
   .min = PARAM_VAL_##type_(min_), \
   .max = PARAM_VAL_##type_(max_), \
   .def = PARAM_VAL_##type_(def_), \
   .choices = (choices_), \
   .id = (id_), \
   .offset = (uint16_t)offsetof(param_values_t, sym), \
   .type = (uint8_t)PARAM_T_##type_, \
   .flags = (uint8_t)(flags_)},
    PARAM_LIST(PARAM_X_INFO)
#undef PARAM_X_INFO
};

/* Every member is 4 bytes, so a value moves in and out of the struct by memcpy at its
 * offset whatever its type. */
_Static_assert(sizeof(float) == 4 && sizeof(uint32_t) == 4, "4-byte parameter values");
_Static_assert(sizeof(param_values_t) == 4u * PARAM_COUNT, "param_values_t has no padding");

const param_info_t *param_info(param_idx_t i)
{
  return ((unsigned)i < (unsigned)PARAM_COUNT) ? &k_param_table[i] : NULL;
}

param_idx_t param_lookup(const char *name, size_t len)
{
  if (name == NULL) {
    return PARAM_COUNT;
  }
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const char *n = k_param_table[i].name;
    if (strlen(n) == len && memcmp(n, name, len) == 0) {
      return (param_idx_t)i;
    }
  }
  return PARAM_COUNT;
}

param_idx_t param_lookup_id(uint16_t id)
{
  /* A switch on the ids: a duplicate id in param_list.h is a compile error here. */
  switch (id) {
#define PARAM_X_CASE(sym, id_, ...) \
  case (id_): return PARAM_##sym;
    PARAM_LIST(PARAM_X_CASE)
#undef PARAM_X_CASE
  default: return PARAM_COUNT;
  }
}

param_value_t param_get(const param_values_t *v, param_idx_t i)
{
  param_value_t out = {.u = 0u};
  if ((unsigned)i < (unsigned)PARAM_COUNT) {
    memcpy(&out, (const uint8_t *)v + k_param_table[i].offset, sizeof out);
  }
  return out;
}

void param_put(param_values_t *v, param_idx_t i, param_value_t val)
{
  if ((unsigned)i < (unsigned)PARAM_COUNT) {
    /* -0 and 0 are one value: stored as +0, so diff, the flash image and the
     * unchanged-save check see one bit pattern for it. */
    if (k_param_table[i].type == (uint8_t)PARAM_T_F32 && val.f == 0.0f) {
      val.u = 0u;
    }
    memcpy((uint8_t *)v + k_param_table[i].offset, &val, sizeof val);
  }
}

param_status_t param_check(param_idx_t i, param_value_t val)
{
  const param_info_t *pi = param_info(i);
  if (pi == NULL) {
    return PARAM_ERR_UNKNOWN;
  }
  switch ((param_type_t)pi->type) {
  case PARAM_T_F32:
    if (!isfinite(val.f)) {
      return PARAM_ERR_NOT_FINITE;
    }
    /* A subnormal means nothing to any parameter, and the FPU with flush-to-zero on
     * would run a 0 where the bank holds something else. */
    if (fpclassify(val.f) == FP_SUBNORMAL) {
      return PARAM_ERR_RANGE;
    }
    return (val.f >= pi->min.f && val.f <= pi->max.f) ? PARAM_OK : PARAM_ERR_RANGE;
  case PARAM_T_ENUM:
    if (val.u > 31u || (pi->choices & (1u << val.u)) == 0u) {
      return PARAM_ERR_CHOICE;
    }
    return (val.u >= pi->min.u && val.u <= pi->max.u) ? PARAM_OK : PARAM_ERR_CHOICE;
  case PARAM_T_U32:
    return (val.u >= pi->min.u && val.u <= pi->max.u) ? PARAM_OK : PARAM_ERR_RANGE;
  default: return PARAM_ERR_UNKNOWN;
  }
}

bool param_value_equal(param_idx_t i, param_value_t a, param_value_t b)
{
  (void)i; /* both types compare by their 32 bits */
  return a.u == b.u;
}

void param_values_defaults(param_values_t *v)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    param_put(v, (param_idx_t)i, k_param_table[i].def);
  }
}

const char *param_status_str(param_status_t st)
{
  switch (st) {
  case PARAM_OK: return "ok";
  case PARAM_ERR_UNKNOWN: return "unknown parameter";
  case PARAM_ERR_READONLY: return "read-only";
  case PARAM_ERR_RANGE: return "out of range";
  case PARAM_ERR_NOT_FINITE: return "not finite";
  case PARAM_ERR_CHOICE: return "not an allowed choice";
  case PARAM_ERR_BUSY: return "drive running: stop the drive first";
  case PARAM_ERR_PENDING: return "previous change not yet taken by the sample loop, retry";
  case PARAM_ERR_REJECTED: return "rejected by the application";
  default: return "?";
  }
}

/* ---- bank ---- */

static uint32_t active_index(const params_t *p)
{
  return atomic_load_explicit(&p->published, memory_order_relaxed) & 1u;
}

static void set_err(params_err_t *err, const char *why, param_idx_t idx)
{
  if (err != NULL) {
    err->why = why;
    err->idx = idx;
  }
}

static param_status_t check_all(const param_values_t *v, params_err_t *err)
{
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_status_t st = param_check((param_idx_t)i, param_get(v, (param_idx_t)i));
    if (st != PARAM_OK) {
      set_err(err, NULL, (param_idx_t)i);
      return st;
    }
  }
  return PARAM_OK;
}

param_status_t params_init(params_t *p, const params_cfg_t *cfg, const param_values_t *initial,
                           params_err_t *err)
{
  memset(p, 0, sizeof *p);
  p->cfg = *cfg;
  set_err(err, NULL, PARAM_COUNT);
  if (initial != NULL) {
    p->block[0] = *initial;
  } else {
    param_values_defaults(&p->block[0]);
  }
  param_status_t st = check_all(&p->block[0], err);
  if (st != PARAM_OK) {
    return st;
  }
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    param_put(&p->block[0], (param_idx_t)i, param_get(&p->block[0], (param_idx_t)i)); /* -0 */
  }
  if (p->cfg.derive != NULL) {
    const char *why = NULL;
    if (p->cfg.derive(p->cfg.ctx, &p->block[0], p->cfg.derived[0], &why) != 0) {
      set_err(err, why, PARAM_COUNT);
      return PARAM_ERR_REJECTED;
    }
  }
  p->block[1] = p->block[0];
  p->staged = p->block[0];
  atomic_store_explicit(&p->published, 0u, memory_order_relaxed);
  atomic_store_explicit(&p->ack, 0u, memory_order_relaxed);
  return PARAM_OK;
}

param_status_t params_stage(params_t *p, param_idx_t i, param_value_t val)
{
  const param_info_t *pi = param_info(i);
  if (pi == NULL) {
    return PARAM_ERR_UNKNOWN;
  }
  if ((pi->flags & PF_READONLY) != 0u) {
    return PARAM_ERR_READONLY;
  }
  const param_status_t st = param_check(i, val);
  if (st == PARAM_OK) {
    param_put(&p->staged, i, val);
  }
  return st;
}

param_status_t params_stage_all(params_t *p, const param_values_t *v, params_err_t *err)
{
  set_err(err, NULL, PARAM_COUNT);
  param_values_t next = p->staged;
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    if ((k_param_table[i].flags & PF_READONLY) != 0u) {
      continue;
    }
    const param_value_t val = param_get(v, (param_idx_t)i);
    const param_status_t st = param_check((param_idx_t)i, val);
    if (st != PARAM_OK) {
      set_err(err, NULL, (param_idx_t)i);
      return st;
    }
    param_put(&next, (param_idx_t)i, val);
  }
  p->staged = next;
  return PARAM_OK;
}

void params_discard(params_t *p) { p->staged = p->block[active_index(p)]; }

param_status_t params_commit(params_t *p, params_err_t *err)
{
  set_err(err, NULL, PARAM_COUNT);
  const uint32_t seq = atomic_load_explicit(&p->published, memory_order_relaxed);
  const uint32_t ack = atomic_load_explicit(&p->ack, memory_order_relaxed);
  atomic_signal_fence(memory_order_acquire);
  const param_values_t *cur = &p->block[seq & 1u];
  if (ack != seq) {
    /* the ISR may still be running a tick on the other block */
    p->staged = *cur;
    return PARAM_ERR_PENDING;
  }
  if (memcmp(&p->staged, cur, sizeof *cur) == 0) {
    return PARAM_OK; /* nothing to publish */
  }
  const bool safe = params_loop_safe(p);
  for (unsigned i = 0; i < (unsigned)PARAM_COUNT; i++) {
    const param_idx_t idx = (param_idx_t)i;
    if ((k_param_table[i].flags & PF_LIVE) == 0u && !safe &&
        !param_value_equal(idx, param_get(&p->staged, idx), param_get(cur, idx))) {
      set_err(err, NULL, idx);
      p->staged = *cur;
      return PARAM_ERR_BUSY;
    }
  }
  const uint32_t nxt = (seq + 1u) & 1u;
  p->block[nxt] = p->staged;
  if (p->cfg.derive != NULL) {
    const char *why = NULL;
    if (p->cfg.derive(p->cfg.ctx, &p->block[nxt], p->cfg.derived[nxt], &why) != 0) {
      set_err(err, why, PARAM_COUNT);
      p->staged = *cur;
      return PARAM_ERR_REJECTED;
    }
  }
  /* block and derived data complete before the ISR can see the new counter */
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&p->published, seq + 1u, memory_order_relaxed);
  return PARAM_OK;
}

param_status_t params_set(params_t *p, param_idx_t i, param_value_t val, params_err_t *err)
{
  set_err(err, NULL, i);
  const param_status_t st = params_stage(p, i, val);
  if (st != PARAM_OK) {
    return st;
  }
  return params_commit(p, err);
}

const param_values_t *params_current(const params_t *p) { return &p->block[active_index(p)]; }

const void *params_current_derived(const params_t *p)
{
  return p->cfg.derived[active_index(p)];
}

const param_values_t *params_staged(const params_t *p) { return &p->staged; }

bool params_loop_safe(const params_t *p)
{
  return (p->cfg.loop_safe != NULL) ? p->cfg.loop_safe(p->cfg.ctx) : false;
}
