/* Single-producer single-consumer byte ring between an interrupt handler and the
 * background loop (no locks: each index has one writer).
 *
 * State: head and tail are free-running uint32 counters; used = head - tail (mod 2^32),
 * slot of a counter = counter & (size - 1). size is a power of two, so the ring holds
 * all size bytes (no wasted slot) and the counters may wrap freely. The producer writes
 * the byte, then publishes head; the consumer reads the byte, then publishes tail. */
#ifndef STM32F4_RING_H
#define STM32F4_RING_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
  uint8_t *buf;
  uint32_t mask;          /* size - 1 */
  volatile uint32_t head; /* written by the producer only */
  volatile uint32_t tail; /* written by the consumer only */
} stm32f4_ring_t;

typedef struct {
  uint8_t *storage;
  uint32_t size; /* bytes; power of two, >= 2 */
} stm32f4_ring_cfg_t;

/* Returns 0, or -1 (ring unchanged) if the storage is missing or size is no power of two. */
int stm32f4_ring_init(stm32f4_ring_t *r, const stm32f4_ring_cfg_t *cfg);
uint32_t stm32f4_ring_used(const stm32f4_ring_t *r);
uint32_t stm32f4_ring_free(const stm32f4_ring_t *r);
/* Producer side: 1 if stored, 0 if the ring was full (byte not stored). */
int stm32f4_ring_put(stm32f4_ring_t *r, uint8_t byte);
/* Consumer side: 1 if a byte was taken, 0 if the ring was empty. */
int stm32f4_ring_get(stm32f4_ring_t *r, uint8_t *byte);
/* Block forms: the number of bytes moved (as many as fit / as many as were there). */
size_t stm32f4_ring_write(stm32f4_ring_t *r, const uint8_t *data, size_t len);
size_t stm32f4_ring_read(stm32f4_ring_t *r, uint8_t *buf, size_t max);

#endif /* STM32F4_RING_H */
