/* A loop's "settled": inside its band for a number of updates in a row (quadrature
 * nulling, quad_null.h; force rebalance, sense_fr.h). */
#ifndef SETTLE_COUNT_H
#define SETTLE_COUNT_H

#include <stdint.h>

/* The updates in a row inside the band after this one: one more (up to needed) when
 * inside, else 0; the loop is settled once it reaches needed. */
static inline uint32_t settle_count(uint32_t in_band, int inside, uint32_t needed)
{
  if (!inside) return 0u;
  return in_band < needed ? in_band + 1u : in_band;
}

#endif /* SETTLE_COUNT_H */
