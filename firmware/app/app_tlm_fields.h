/* The application's telemetry field table: every quantity the `stream` command can
 * select, as a 4-byte word of the gyro's per-tick output snapshot gyro_out_t
 * (gyro/gyro.h), registered with the telemetry module (comm/tlm_fields.h).
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
 * The table holds at most 32 rows (the selection mask is one 32-bit word); append new
 * rows at the end so that existing bit positions keep their meaning.
 */
#ifndef APP_TLM_FIELDS_H
#define APP_TLM_FIELDS_H

#include <stddef.h>
#include <stdint.h>

#include "comm/tlm_fields.h"

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
  X(rate_valid,      U32, "-") \
  X(f_drive_hz,      F32, "Hz") \
  X(rate_invalid,    U32, "-")
/* clang-format on */

typedef enum {
#define TLM_X_IDX(member, type, unit) TLM_FIELD_##member,
  TLM_FIELD_LIST(TLM_X_IDX)
#undef TLM_X_IDX
      TLM_FIELD_COUNT
} tlm_field_idx_t;

/* Mask of every field (a shift by 32, UB, when the table holds 32 fields is avoided). */
#define TLM_FIELD_MASK_ALL ((uint32_t)(0xFFFFFFFFu >> (32u - (uint32_t)TLM_FIELD_COUNT)))

/* The table, for tlm_cfg_t.fields and tlm_plan. */
extern const tlm_fields_t app_tlm_fields;

/* Row i (NULL if i >= TLM_FIELD_COUNT), and the index of a name (TLM_FIELD_COUNT if
 * none), in this table. */
const tlm_field_t *app_tlm_field(uint32_t i);
uint32_t app_tlm_field_lookup(const char *name, size_t len);

#endif /* APP_TLM_FIELDS_H */
