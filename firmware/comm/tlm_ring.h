/* Lock-free single-producer / single-consumer ring of 32-bit words between the sample
 * ISR (producer: one telemetry record per decimated tick) and the background loop
 * (consumer: frames for the UART).
 *
 * State layout:
 *   w[TLM_RING_WORDS]  storage; word i of the stream lives at w[i & (TLM_RING_WORDS-1)]
 *   head               words ever pushed (mod 2^32), written by the producer only
 *   tail               words ever consumed (mod 2^32), written by the consumer only
 *   overruns           records refused because the ring was full, producer only
 * used = head - tail (unsigned, wraps correctly because TLM_RING_WORDS is a power of two
 * no larger than 2^31); free = TLM_RING_WORDS - used.
 *
 * Ordering, as in params.h: the producer writes the words, then a release signal fence,
 * then one 32-bit store of head; the consumer loads head, an acquire signal fence, reads
 * the words, a release signal fence, then stores tail. On the single Cortex-M4 core the
 * ISR preempts the background loop, and a signal fence is exactly the compiler barrier
 * that orders the two across that preemption; 32-bit aligned loads and stores are
 * single-copy atomic. No critical section, and the producer never waits: a record that
 * does not fit whole is dropped and counted (never a partial record, never blocking).
 */
#ifndef TLM_RING_H
#define TLM_RING_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

/* 8 KB: 113 ms of 17 fields at 1 kHz (18 words per record), 2 s of 4 fields at 200 Hz;
 * the background loop drains it every pass, a flash erase stalls it for up to 500 ms. */
#define TLM_RING_WORDS 2048u

_Static_assert((TLM_RING_WORDS & (TLM_RING_WORDS - 1u)) == 0u, "power of two");

typedef struct {
  uint32_t w[TLM_RING_WORDS];
  _Atomic uint32_t head;
  _Atomic uint32_t tail;
  _Atomic uint32_t overruns;
} tlm_ring_t;

void tlm_ring_init(tlm_ring_t *r);

/* Producer: append n words as one record, or nothing (and count an overrun) if they do
 * not all fit. Returns true if appended. n must be >= 1 and <= TLM_RING_WORDS. */
bool tlm_ring_push(tlm_ring_t *r, const uint32_t *w, uint32_t n);

/* Consumer: words available. */
uint32_t tlm_ring_used(const tlm_ring_t *r);
/* Consumer: copy the next n words without consuming them; false (nothing copied) if
 * fewer than n are available. */
bool tlm_ring_peek(const tlm_ring_t *r, uint32_t *w, uint32_t n);
/* Consumer: drop the next n words (at most what is available). */
void tlm_ring_consume(tlm_ring_t *r, uint32_t n);
/* Consumer: drop everything available now. */
void tlm_ring_discard(tlm_ring_t *r);
/* Records refused so far (the counter wraps at 2^32). */
uint32_t tlm_ring_overruns(const tlm_ring_t *r);

#endif /* TLM_RING_H */
