/* A telemetry field table: the quantities a stream can select, each one 4-byte word of
 * a snapshot the application fills every tick. The telemetry module knows no snapshot
 * type: the application registers its table (tlm_cfg_t.fields) and hands the ISR a
 * pointer to its snapshot (tlm_isr_push). The header frame carries each selected row's
 * name and type, which the host decoders read instead of keeping a copy.
 *
 * A record holds the selected fields in table order (bit i of the selection mask is row
 * i), whatever order the command named them in. A table holds 1 to TLM_FIELDS_MAX (32)
 * rows: the mask is one 32-bit word.
 */
#ifndef TLM_FIELDS_H
#define TLM_FIELDS_H

#include <stddef.h>
#include <stdint.h>

typedef enum { TLM_T_F32 = 0, TLM_T_U32 = 1 } tlm_type_t;

typedef struct {
  const char *name; /* on the wire; at most TLM_NAME_MAX bytes */
  const char *unit; /* printed by `stream` with no arguments; "-" for dimensionless */
  uint16_t offset;  /* of the word in the snapshot, a multiple of 4 */
  uint8_t type;     /* tlm_type_t */
} tlm_field_t;

typedef struct {
  const tlm_field_t *row;
  uint32_t count;
} tlm_fields_t;

/* Index by name (exact, len bytes, need not be NUL-terminated); f->count if none. */
uint32_t tlm_fields_lookup(const tlm_fields_t *f, const char *name, size_t len);
/* Mask of every row (a shift by 32, UB, when the table holds 32 rows is avoided). */
static inline uint32_t tlm_fields_mask_all(const tlm_fields_t *f)
{
  return (uint32_t)(0xFFFFFFFFu >> (32u - f->count));
}

#endif /* TLM_FIELDS_H */
