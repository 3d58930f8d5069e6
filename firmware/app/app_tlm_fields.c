#include "app/app_tlm_fields.h"

#include "comm/tlm_frame.h"
#include "gyro/gyro.h"

#define TLM_X_ROW(member, type, unit) \
  {#member, unit, (uint16_t)offsetof(gyro_out_t, member), (uint8_t)TLM_T_##type},
static const tlm_field_t k_rows[TLM_FIELD_COUNT] = {TLM_FIELD_LIST(TLM_X_ROW)};
#undef TLM_X_ROW

const tlm_fields_t app_tlm_fields = {k_rows, (uint32_t)TLM_FIELD_COUNT};

/* Every field is one aligned 4-byte word of the snapshot, so the ISR copies words and a
 * record never holds a torn value; the type letter must match the member's C type. */
#define TLM_X_CHECK(member, type, unit) \
  _Static_assert(sizeof(((gyro_out_t *)0)->member) == 4u, #member " is not 4 bytes"); \
  _Static_assert(offsetof(gyro_out_t, member) % 4u == 0u, #member " is not aligned"); \
  _Static_assert(_Generic(((gyro_out_t *)0)->member, float \
                          : TLM_T_F32, uint32_t \
                          : TLM_T_U32) == TLM_T_##type, \
                 #member " has another type"); \
  _Static_assert(sizeof #member - 1u <= TLM_NAME_MAX, #member " is too long a name");
TLM_FIELD_LIST(TLM_X_CHECK)
#undef TLM_X_CHECK
/* The selection is one 32-bit mask (tlm.h: tlm_isr_sel_t), and a header frame lists at
 * most TLM_FIELDS_MAX fields (tlm_frame.h). */
_Static_assert(TLM_FIELD_COUNT >= 1 && TLM_FIELD_COUNT <= 32, "the selection mask has 32 bits");
_Static_assert(TLM_FIELD_COUNT <= TLM_FIELDS_MAX, "a header lists every field");

const tlm_field_t *app_tlm_field(uint32_t i)
{
  return (i < (uint32_t)TLM_FIELD_COUNT) ? &k_rows[i] : NULL;
}

uint32_t app_tlm_field_lookup(const char *name, size_t len)
{
  return tlm_fields_lookup(&app_tlm_fields, name, len);
}
