/* Single-producer single-consumer byte ring between an interrupt handler and the
 * background loop (no locks: each index has one writer). Shared by every port (the UART
 * drivers' RX and TX queues); header-only, so that the handlers that use it inline it
 * and it runs from wherever they run (SRAM, on a part whose flash stalls while erasing).
 *
 * The same idiom as the firmware's telemetry ring (firmware/comm/tlm_ring.h): head and
 * tail are free-running _Atomic uint32 counters, used = head - tail (mod 2^32), slot of a
 * counter = counter & (size - 1); size is a power of two, so the ring holds all size
 * bytes (no wasted slot) and the counters may wrap freely. The producer writes the
 * byte, a release signal fence, then stores head; the consumer loads head, an acquire
 * signal fence, reads the byte, a release signal fence, then stores tail. On a single
 * core the handler preempts the loop, and a signal fence is exactly the compiler
 * barrier that orders the two across that preemption; aligned 32-bit loads and stores
 * are single-copy atomic, so the counters are read and written with relaxed order.
 * (Why two rings and not one: the telemetry ring moves whole records of 32-bit words,
 * all or nothing, from the sample interrupt; a byte ring would quadruple its stores.) */
#ifndef BYTE_RING_H
#define BYTE_RING_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

/* Always inlined: an out-of-line copy would land in .text (flash), outside the SRAM
 * section the UART handlers run from. */
#define BYTE_RING_FN static inline __attribute__((always_inline))

typedef struct {
  uint8_t *buf;
  uint32_t mask;         /* size - 1 */
  _Atomic uint32_t head; /* written by the producer only */
  _Atomic uint32_t tail; /* written by the consumer only */
} byte_ring_t;

typedef struct {
  uint8_t *storage;
  uint32_t size; /* bytes; power of two, >= 2 */
} byte_ring_cfg_t;

/* Returns 0, or -1 (ring unchanged) if the storage is missing or size is no power of two. */
BYTE_RING_FN int byte_ring_init(byte_ring_t *r, const byte_ring_cfg_t *cfg)
{
  if (r == NULL || cfg == NULL || cfg->storage == NULL || cfg->size < 2u ||
      (cfg->size & (cfg->size - 1u)) != 0u) {
    return -1;
  }
  r->buf = cfg->storage;
  r->mask = cfg->size - 1u;
  atomic_store_explicit(&r->head, 0u, memory_order_relaxed);
  atomic_store_explicit(&r->tail, 0u, memory_order_relaxed);
  return 0;
}

BYTE_RING_FN uint32_t byte_ring_used(const byte_ring_t *r)
{
  return atomic_load_explicit(&r->head, memory_order_relaxed) -
         atomic_load_explicit(&r->tail, memory_order_relaxed);
}

BYTE_RING_FN uint32_t byte_ring_free(const byte_ring_t *r)
{
  return (r->mask + 1u) - byte_ring_used(r);
}

/* Producer side: 1 if stored, 0 if the ring was full (byte not stored). */
BYTE_RING_FN int byte_ring_put(byte_ring_t *r, uint8_t byte)
{
  const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
  if (head - atomic_load_explicit(&r->tail, memory_order_relaxed) > r->mask) return 0;
  r->buf[head & r->mask] = byte;
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&r->head, head + 1u, memory_order_relaxed);
  return 1;
}

/* Consumer side: 1 if a byte was taken, 0 if the ring was empty. */
BYTE_RING_FN int byte_ring_get(byte_ring_t *r, uint8_t *byte)
{
  const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  if (atomic_load_explicit(&r->head, memory_order_relaxed) == tail) return 0;
  atomic_signal_fence(memory_order_acquire);
  *byte = r->buf[tail & r->mask];
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&r->tail, tail + 1u, memory_order_relaxed);
  return 1;
}

/* Block forms: the number of bytes moved (as many as fit / as many as were there). */
BYTE_RING_FN size_t byte_ring_write(byte_ring_t *r, const uint8_t *data, size_t len)
{
  size_t n = 0u;
  while (n < len && byte_ring_put(r, data[n])) ++n;
  return n;
}

BYTE_RING_FN size_t byte_ring_read(byte_ring_t *r, uint8_t *buf, size_t max)
{
  size_t n = 0u;
  while (n < max && byte_ring_get(r, &buf[n])) ++n;
  return n;
}

#endif /* BYTE_RING_H */
