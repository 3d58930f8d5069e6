#include "stm32f4_ring.h"

#include "stm32f4_core.h"

/* Keeps the compiler from moving the data access across the index update; a single
 * Cortex-M4 core sees its own stores in order, so no hardware barrier is needed. */
#define RING_FENCE() __atomic_signal_fence(__ATOMIC_SEQ_CST)

int stm32f4_ring_init(stm32f4_ring_t *r, const stm32f4_ring_cfg_t *cfg)
{
  if (r == 0 || cfg == 0 || cfg->storage == 0 || cfg->size < 2u ||
      (cfg->size & (cfg->size - 1u)) != 0u) {
    return -1;
  }
  r->buf = cfg->storage;
  r->mask = cfg->size - 1u;
  r->head = 0u;
  r->tail = 0u;
  return 0;
}

STM32F4_RAMFUNC uint32_t stm32f4_ring_used(const stm32f4_ring_t *r)
{
  return r->head - r->tail;
}

STM32F4_RAMFUNC uint32_t stm32f4_ring_free(const stm32f4_ring_t *r)
{
  return (r->mask + 1u) - (r->head - r->tail);
}

STM32F4_RAMFUNC int stm32f4_ring_put(stm32f4_ring_t *r, uint8_t byte)
{
  const uint32_t head = r->head;
  if (head - r->tail > r->mask) return 0;
  r->buf[head & r->mask] = byte;
  RING_FENCE();
  r->head = head + 1u;
  return 1;
}

STM32F4_RAMFUNC int stm32f4_ring_get(stm32f4_ring_t *r, uint8_t *byte)
{
  const uint32_t tail = r->tail;
  if (r->head == tail) return 0;
  *byte = r->buf[tail & r->mask];
  RING_FENCE();
  r->tail = tail + 1u;
  return 1;
}

size_t stm32f4_ring_write(stm32f4_ring_t *r, const uint8_t *data, size_t len)
{
  size_t n = 0u;
  while (n < len && stm32f4_ring_put(r, data[n])) {
    ++n;
  }
  return n;
}

size_t stm32f4_ring_read(stm32f4_ring_t *r, uint8_t *buf, size_t max)
{
  size_t n = 0u;
  while (n < max && stm32f4_ring_get(r, &buf[n])) {
    ++n;
  }
  return n;
}
