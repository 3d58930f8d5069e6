/* The telemetry SPSC ring judged against a reference model (a plain FIFO of records of
 * unbounded size that knows which pushes the ring had to refuse): records of varying
 * length are pushed and consumed in a pseudo-random interleaving, including pushes that
 * land between the consumer's peek and its consume (the ISR preempting the background
 * loop), and across the 2^32 wrap of the indices. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "comm/tlm_ring.h"

static tlm_ring_t ring;

static uint32_t lcg(uint32_t *s)
{
  *s = *s * 1664525u + 1013904223u;
  return *s >> 8;
}

/* Model: the words a correct ring holds, in order, with each record's length. */
#define MODEL_MAX 400000u
static uint32_t m_words[MODEL_MAX];
static uint32_t m_len[MODEL_MAX];
static size_t m_w_head, m_w_tail, m_r_head, m_r_tail;

static void model_reset(void) { m_w_head = m_w_tail = m_r_head = m_r_tail = 0u; }

static void run_interleaving(uint32_t start_index, uint32_t seed, uint32_t producer_bias)
{
  tlm_ring_init(&ring);
  atomic_store(&ring.head, start_index);
  atomic_store(&ring.tail, start_index);
  model_reset();
  uint32_t s = seed, next_word = 1u, refused = 0u, pushed = 0u, popped = 0u;
  for (int step = 0; step < 20000; step++) {
    const uint32_t r = lcg(&s) % 100u;
    if (r < producer_bias) {
      /* producer: one record of 1..17 words */
      const uint32_t n = 1u + lcg(&s) % 17u;
      uint32_t rec[17];
      for (uint32_t i = 0; i < n; i++) rec[i] = next_word + i;
      const uint32_t free_words = TLM_RING_WORDS - (uint32_t)(m_w_head - m_w_tail);
      const bool ok = tlm_ring_push(&ring, rec, n);
      assert_int_equal(ok, n <= free_words);
      if (ok) {
        for (uint32_t i = 0; i < n; i++) m_words[m_w_head++] = rec[i];
        m_len[m_r_head++] = n;
        pushed++;
      } else {
        refused++;
      }
      next_word += n;
    } else if (m_r_tail < m_r_head) {
      /* consumer: the oldest record, with a push in between peek and consume */
      const uint32_t n = m_len[m_r_tail];
      uint32_t got[17];
      assert_true(tlm_ring_peek(&ring, got, n));
      if (lcg(&s) % 4u == 0u) {
        const uint32_t w = 0xDEAD0000u + next_word;
        const uint32_t free_words = TLM_RING_WORDS - (uint32_t)(m_w_head - m_w_tail);
        const bool ok = tlm_ring_push(&ring, &w, 1u);
        assert_int_equal(ok, free_words >= 1u);
        if (ok) {
          m_words[m_w_head++] = w;
          m_len[m_r_head++] = 1u;
          pushed++;
        } else {
          refused++;
        }
        next_word++;
      }
      assert_memory_equal(got, &m_words[m_w_tail], n * sizeof got[0]);
      tlm_ring_consume(&ring, n);
      m_w_tail += n;
      m_r_tail++;
      popped++;
    }
    assert_int_equal(tlm_ring_used(&ring), (uint32_t)(m_w_head - m_w_tail));
    assert_int_equal(tlm_ring_overruns(&ring), refused);
    assert_true(m_w_head < MODEL_MAX - 40u);
  }
  /* both regimes happened: the test is not vacuous */
  assert_true(pushed > 1000u && popped > 1000u);
  if (producer_bias > 50u) {
    assert_true(refused > 100u);
  }
}

static void test_interleaved_consumer_keeps_up(void **state)
{
  (void)state;
  run_interleaving(0u, 1u, 45u);
}

static void test_interleaved_overrun(void **state)
{
  (void)state;
  run_interleaving(0u, 2u, 70u);
}

static void test_interleaved_across_index_wrap(void **state)
{
  (void)state;
  run_interleaving(0xFFFFF000u, 3u, 60u);
  run_interleaving(0x7FFFFF00u, 4u, 60u);
}

/* A record fits whole or not at all; the ring fills to exactly TLM_RING_WORDS. */
static void test_whole_records_only(void **state)
{
  (void)state;
  tlm_ring_init(&ring);
  uint32_t rec[16];
  for (uint32_t i = 0; i < 16u; i++) rec[i] = i;
  for (uint32_t k = 0; k < TLM_RING_WORDS / 16u; k++)
    assert_true(tlm_ring_push(&ring, rec, 16u));
  assert_int_equal(tlm_ring_used(&ring), TLM_RING_WORDS);
  assert_false(tlm_ring_push(&ring, rec, 1u));
  assert_int_equal(tlm_ring_overruns(&ring), 1u);
  tlm_ring_consume(&ring, 3u);
  assert_false(tlm_ring_push(&ring, rec, 4u)); /* 3 free: the 4-word record is refused */
  assert_int_equal(tlm_ring_used(&ring), TLM_RING_WORDS - 3u);
  assert_true(tlm_ring_push(&ring, rec, 3u));
  assert_int_equal(tlm_ring_overruns(&ring), 2u);
  /* peek of more than is there copies nothing */
  tlm_ring_discard(&ring);
  uint32_t out[4] = {7u, 7u, 7u, 7u};
  assert_true(tlm_ring_push(&ring, rec, 2u));
  assert_false(tlm_ring_peek(&ring, out, 3u));
  assert_int_equal(out[0], 7u);
  tlm_ring_consume(&ring, 99u); /* consume is bounded by what is there */
  assert_int_equal(tlm_ring_used(&ring), 0u);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_interleaved_consumer_keeps_up),
      cmocka_unit_test(test_interleaved_overrun),
      cmocka_unit_test(test_interleaved_across_index_wrap),
      cmocka_unit_test(test_whole_records_only),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
