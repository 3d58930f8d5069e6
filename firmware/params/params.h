/* Parameters: the metadata table generated from param_list.h, validation, and the
 * double-buffered bank through which the 50 kHz ISR reads them.
 *
 * Why a bank: a PI gain pair, a bias polynomial or a filter and its coefficients must
 * change together. Writing live variables from the background loop would let the ISR
 * run one tick with half of a change (the Crazyflie habit to avoid). Instead:
 *
 *   staged      shadow copy edited by params_stage*() (background only)
 *   block[0/1]  value blocks; block[published & 1] is active, the other is free
 *   derived[0/1] application-owned blocks of quantities derived from the values
 *               (filter coefficients, discretised PI), one per value block
 *   published   publish counter, written by the background loop only
 *   ack         last publish counter the ISR picked up, written by the ISR only
 *
 * Commit (background): refuse with PARAM_ERR_PENDING unless ack == published (the ISR
 * has moved to the active block, so the other one is no longer read); copy staged into
 * the free block; call derive() on it (outside the ISR; it may reject the change);
 * then one 32-bit store published + 1 publishes it. The ISR, at the start of every
 * tick, loads published, stores it to ack and uses block[published & 1] for the whole
 * tick: it sees either the old or the new block entire, never a mix. No critical section
 * is needed: each counter has one writer, 32-bit loads/stores are single-copy atomic on
 * the Cortex-M4, and the signal fences order the block writes before the publish (the
 * ISR preempts the background loop on one core, which is what a signal fence orders).
 * A rejected or refused commit changes nothing: staged is reset to the active values.
 *
 * Non-live parameters (no PF_LIVE) may only change while the application's loop_safe()
 * says the loop is in a safe mode (drive off); otherwise commit returns PARAM_ERR_BUSY.
 */
#ifndef PARAMS_H
#define PARAMS_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

enum {
  PF_PERSIST = 1u << 0,  /* saved to flash */
  PF_READONLY = 1u << 1, /* set refused */
  PF_LIVE = 1u << 2,     /* may change while the drive runs */
  PF_RESTART = 1u << 3   /* read by the application at start-up only */
};

#include "params/param_list.h"

typedef enum { PARAM_T_F32 = 0, PARAM_T_U32 = 1, PARAM_T_ENUM = 2 } param_type_t;

typedef union {
  float f;
  uint32_t u;
} param_value_t;

typedef enum {
#define PARAM_X_IDX(sym, ...) PARAM_##sym,
  PARAM_LIST(PARAM_X_IDX)
#undef PARAM_X_IDX
      PARAM_COUNT
} param_idx_t;

#define PARAM_CTYPE_F32 float
#define PARAM_CTYPE_U32 uint32_t
#define PARAM_CTYPE_ENUM uint32_t

/* Every parameter as a typed member, so the ISR reads v->drive_amp_kp directly. */
typedef struct {
#define PARAM_X_MEMBER(sym, id, name, type, ...) PARAM_CTYPE_##type sym;
  PARAM_LIST(PARAM_X_MEMBER)
#undef PARAM_X_MEMBER
} param_values_t;

typedef struct {
  const char *name;
  const char *unit;
  const char *help;
  param_value_t min, max, def;
  uint32_t choices; /* PARAM_T_ENUM: bit v set <=> value v allowed */
  uint16_t id;      /* stable flash record id */
  uint16_t offset;  /* of the member in param_values_t */
  uint8_t type;     /* param_type_t */
  uint8_t flags;    /* PF_* */
} param_info_t;

typedef enum {
  PARAM_OK = 0,
  PARAM_ERR_UNKNOWN,    /* no such parameter */
  PARAM_ERR_READONLY,   /* PF_READONLY */
  PARAM_ERR_RANGE,      /* outside [min, max] */
  PARAM_ERR_NOT_FINITE, /* NaN or infinity */
  PARAM_ERR_CHOICE,     /* ENUM value not among the choices */
  PARAM_ERR_BUSY,       /* non-live parameter while the loop is not in a safe mode */
  PARAM_ERR_PENDING,    /* the ISR has not yet taken the previous change; retry */
  PARAM_ERR_REJECTED    /* the application's derive() refused the set */
} param_status_t;

/* ---- table and values (pure functions) ---- */

const param_info_t *param_info(param_idx_t i); /* NULL if i >= PARAM_COUNT */
/* Index by CLI name (exact, len bytes, need not be NUL-terminated); PARAM_COUNT if none. */
param_idx_t param_lookup(const char *name, size_t len);
/* Index by flash record id; PARAM_COUNT if none. */
param_idx_t param_lookup_id(uint16_t id);
param_value_t param_get(const param_values_t *v, param_idx_t i);
/* Type, finiteness, range and choice check; a subnormal float is out of range
 * (read-only-ness is the bank's business). */
param_status_t param_check(param_idx_t i, param_value_t val);
/* Bitwise equality of two values of parameter i (param_put never stores a -0). */
bool param_value_equal(param_idx_t i, param_value_t a, param_value_t b);
void param_values_defaults(param_values_t *v);
/* Unchecked write of one member (callers have run param_check); a float -0 is written as
 * +0, so every way into a value set (command line, flash record, simulator) normalises. */
void param_put(param_values_t *v, param_idx_t i, param_value_t val);
const char *param_status_str(param_status_t st);

/* ---- the bank ---- */

/* Recompute the application's derived block from v (background loop). Return 0 to
 * accept; nonzero to reject the whole change, optionally pointing *why at a static
 * one-line reason. */
typedef int (*params_derive_fn)(void *ctx, const param_values_t *v, void *derived,
                                const char **why);
/* true when the loop is in a safe mode (drive off / not LOCKED). */
typedef bool (*params_loop_safe_fn)(void *ctx);

typedef struct {
  params_derive_fn derive;       /* may be NULL: nothing derived */
  void *derived[2];              /* two application blocks for derive(), or NULL */
  params_loop_safe_fn loop_safe; /* may be NULL: never safe (non-live sets refused) */
  void *ctx;
} params_cfg_t;

typedef struct {
  param_values_t block[2];
  param_values_t staged;
  _Atomic uint32_t published; /* background writes */
  _Atomic uint32_t ack;       /* ISR writes */
  params_cfg_t cfg;
} params_t;

typedef struct {
  const param_values_t *v; /* this tick's values */
  const void *derived;     /* this tick's derived block (NULL if none) */
} params_view_t;

/* Detail of a failed commit: the reason from derive(), or the parameter at fault. */
typedef struct {
  const char *why;
  param_idx_t idx;
} params_err_t;

/* Start from initial (NULL: the defaults; every value is checked) and derive it.
 * Returns PARAM_OK, or the check/derive failure (then *p is unusable). */
param_status_t params_init(params_t *p, const params_cfg_t *cfg, const param_values_t *initial,
                           params_err_t *err);

/* Stage one value (checked; read-only refused). On error staged is unchanged. */
param_status_t params_stage(params_t *p, param_idx_t i, param_value_t val);
/* Stage every writable value of v (read-only ones keep their current value); all
 * checked first, nothing staged on error (err->idx says which). */
param_status_t params_stage_all(params_t *p, const param_values_t *v, params_err_t *err);
/* Drop staged edits. */
void params_discard(params_t *p);
/* Publish the staged values (see the header comment). On any error staged is reset to
 * the active values and the ISR keeps the old block. */
param_status_t params_commit(params_t *p, params_err_t *err);
/* params_stage + params_commit. */
param_status_t params_set(params_t *p, param_idx_t i, param_value_t val, params_err_t *err);

/* Background view of the values the ISR is (or will next tick be) using. */
const param_values_t *params_current(const params_t *p);
/* The derived block of those values (NULL if none); valid until the next commit. */
const void *params_current_derived(const params_t *p);
const param_values_t *params_staged(const params_t *p);
bool params_loop_safe(const params_t *p);

/* ISR: call once at the start of every tick: takes the published generation (and
 * acknowledges it) and returns it; its view (params_isr_view) holds for the whole tick.
 * A commit waits for the acknowledgement, so the ISR sees every generation, in order: a
 * new generation is a new block, which an ISR that keeps the last one it used can tell
 * by comparing two words, without forming the view on every tick. */
static inline uint32_t params_isr_ack(params_t *p)
{
  const uint32_t seq = atomic_load_explicit(&p->published, memory_order_relaxed);
  atomic_signal_fence(memory_order_acquire);
  atomic_store_explicit(&p->ack, seq, memory_order_relaxed);
  return seq;
}

/* ISR: the view of generation seq, taken this tick by params_isr_ack. */
static inline params_view_t params_isr_view(const params_t *p, uint32_t seq)
{
  const uint32_t i = seq & 1u;
  const params_view_t view = {&p->block[i], p->cfg.derived[i]};
  return view;
}

/* ISR: params_isr_ack and its view; use the view for the whole tick. */
static inline params_view_t params_isr_acquire(params_t *p)
{
  return params_isr_view(p, params_isr_ack(p));
}

#endif /* PARAMS_H */
