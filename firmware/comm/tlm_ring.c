#include "comm/tlm_ring.h"

#include <string.h>

#include "dsp/ramfunc.h"

#define MASK (TLM_RING_WORDS - 1u)

void tlm_ring_init(tlm_ring_t *r)
{
  memset(r->w, 0, sizeof r->w);
  atomic_store_explicit(&r->head, 0u, memory_order_relaxed);
  atomic_store_explicit(&r->tail, 0u, memory_order_relaxed);
  atomic_store_explicit(&r->overruns, 0u, memory_order_relaxed);
}

GYRO_RAMFUNC bool tlm_ring_push(tlm_ring_t *r, const uint32_t *w, uint32_t n)
{
  const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
  const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  if (TLM_RING_WORDS - (head - tail) < n) {
    /* single writer: a plain read-modify-write, no LDREX/STREX needed */
    const uint32_t o = atomic_load_explicit(&r->overruns, memory_order_relaxed);
    atomic_store_explicit(&r->overruns, o + 1u, memory_order_relaxed);
    return false;
  }
  for (uint32_t i = 0; i < n; i++) {
    r->w[(head + i) & MASK] = w[i];
  }
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&r->head, head + n, memory_order_relaxed);
  return true;
}

uint32_t tlm_ring_used(const tlm_ring_t *r)
{
  const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
  const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  return head - tail;
}

bool tlm_ring_peek(const tlm_ring_t *r, uint32_t *w, uint32_t n)
{
  const uint32_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
  const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  if (head - tail < n) {
    return false;
  }
  atomic_signal_fence(memory_order_acquire);
  for (uint32_t i = 0; i < n; i++) {
    w[i] = r->w[(tail + i) & MASK];
  }
  return true;
}

void tlm_ring_consume(tlm_ring_t *r, uint32_t n)
{
  const uint32_t used = tlm_ring_used(r);
  const uint32_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
  /* the words were read before the slot is handed back to the producer */
  atomic_signal_fence(memory_order_release);
  atomic_store_explicit(&r->tail, tail + ((n < used) ? n : used), memory_order_relaxed);
}

void tlm_ring_discard(tlm_ring_t *r) { tlm_ring_consume(r, tlm_ring_used(r)); }

uint32_t tlm_ring_overruns(const tlm_ring_t *r)
{
  return atomic_load_explicit(&r->overruns, memory_order_relaxed);
}
