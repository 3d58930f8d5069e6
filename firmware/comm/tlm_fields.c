#include "comm/tlm_fields.h"

#include <string.h>

uint32_t tlm_fields_lookup(const tlm_fields_t *f, const char *name, size_t len)
{
  for (uint32_t i = 0; i < f->count; i++) {
    if (strlen(f->row[i].name) == len && memcmp(f->row[i].name, name, len) == 0) {
      return i;
    }
  }
  return f->count;
}
