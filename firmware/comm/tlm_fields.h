/* The telemetry field table: every quantity the `stream` command can select, as a
 * 4-byte word of the gyro's per-tick output snapshot gyro_out_t (gyro/gyro.h).
 *
 * THE list of streamable fields: the `stream` command (names, validation, the listing
 * it prints), the ISR's record layout and the header frame (names and types, which the
 * host decoders read instead of keeping a copy) all derive from these rows. Adding a
 * field is adding a member to gyro_out_t and one row here.
 *
 * Row: X(member, TYPE, unit)
 *   member  name of the gyro_out_t member; it is also the field's name on the wire and
 *           carries its unit suffix (_dps, _v, _deg, _v2) unless dimensionless
 *   TYPE    F32 (IEEE-754 binary32) or U32
 *   unit    printed by `stream` with no arguments; "-" for dimensionless
 * A record holds the selected fields in table order (bit i of the selection mask is row
 * i), whatever order the command named them in. The table holds at most 32 rows (the
 * mask is one 32-bit word); append new rows at the end so that existing bit positions
 * keep their meaning.
 */
#ifndef TLM_FIELDS_H
#define TLM_FIELDS_H

#include <stddef.h>
#include <stdint.h>

/* clang-format off */
#define TLM_FIELD_LIST(X) \
  X(rate_dps,        F32, "deg/s") \
  X(rate_unc_dps,    F32, "deg/s") \
  X(quad_dps,        F32, "deg/s") \
  X(drive_amp_v,     F32, "V") \
  X(drive_phase_deg, F32, "deg") \
  X(p_deg,           F32, "deg") \
  X(p_f_deg,         F32, "deg") \
  X(f_cmd_v2,        F32, "V^2") \
  X(u1_v,            F32, "V") \
  X(u2_v,            F32, "V") \
  X(sense_i_v,       F32, "V") \
  X(sense_q_v,       F32, "V") \
  X(mode,            U32, "-") \
  X(fault,           U32, "-") \
  X(flags,           U32, "-") \
  X(tick,            U32, "-") \
  X(rate_valid,      U32, "-")
/* clang-format on */

typedef enum { TLM_T_F32 = 0, TLM_T_U32 = 1 } tlm_type_t;

typedef enum {
#define TLM_X_IDX(member, type, unit) TLM_FIELD_##member,
  TLM_FIELD_LIST(TLM_X_IDX)
#undef TLM_X_IDX
  TLM_FIELD_COUNT
} tlm_field_idx_t;

typedef struct {
  const char *name;
  const char *unit;
  uint16_t offset; /* of the member in gyro_out_t */
  uint8_t type;    /* tlm_type_t */
} tlm_field_t;

/* NULL if i >= TLM_FIELD_COUNT. */
const tlm_field_t *tlm_field(uint32_t i);
/* Index by name (exact, len bytes, need not be NUL-terminated); TLM_FIELD_COUNT if none. */
uint32_t tlm_field_lookup(const char *name, size_t len);
/* Mask of every field (a shift by 32, UB, when the table holds 32 fields is avoided). */
#define TLM_FIELD_MASK_ALL ((uint32_t)(0xFFFFFFFFu >> (32u - (uint32_t)TLM_FIELD_COUNT)))

#endif /* TLM_FIELDS_H */
