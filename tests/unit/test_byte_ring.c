/* SPSC byte ring (hal/common/byte_ring.h) against a plain array FIFO model. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <cmocka.h>

#include "byte_ring.h"

static void test_init_validates(void **state)
{
  (void)state;
  uint8_t storage[16];
  byte_ring_t r = {0};
  byte_ring_cfg_t cfg = {storage, 12u};
  assert_int_equal(byte_ring_init(&r, &cfg), -1); /* not a power of two */
  cfg.size = 1u;
  assert_int_equal(byte_ring_init(&r, &cfg), -1);
  cfg.size = 16u;
  cfg.storage = NULL;
  assert_int_equal(byte_ring_init(&r, &cfg), -1);
  assert_null(r.buf); /* unchanged */
  cfg.storage = storage;
  assert_int_equal(byte_ring_init(&r, &cfg), 0);
  assert_int_equal(byte_ring_free(&r), 16);
}

static void test_full_ring_refuses_and_keeps_order(void **state)
{
  (void)state;
  uint8_t storage[8];
  byte_ring_t r;
  const byte_ring_cfg_t cfg = {storage, 8u};
  assert_int_equal(byte_ring_init(&r, &cfg), 0);
  for (uint8_t i = 0; i < 8; ++i) assert_int_equal(byte_ring_put(&r, i), 1);
  assert_int_equal(byte_ring_put(&r, 99), 0); /* overflow: refused, nothing lost */
  assert_int_equal(byte_ring_used(&r), 8);
  assert_int_equal(byte_ring_free(&r), 0);
  uint8_t b;
  for (uint8_t i = 0; i < 8; ++i) {
    assert_int_equal(byte_ring_get(&r, &b), 1);
    assert_int_equal(b, i);
  }
  assert_int_equal(byte_ring_get(&r, &b), 0);
}

static void test_counters_wrap_past_2_pow_32(void **state)
{
  (void)state;
  uint8_t storage[4];
  byte_ring_t r;
  const byte_ring_cfg_t cfg = {storage, 4u};
  assert_int_equal(byte_ring_init(&r, &cfg), 0);
  r.head = r.tail = 0xFFFFFFFEu;
  const uint8_t in[4] = {10, 11, 12, 13};
  assert_int_equal(byte_ring_write(&r, in, 4), 4);
  assert_int_equal(r.head, 2u); /* wrapped */
  assert_int_equal(byte_ring_used(&r), 4);
  assert_int_equal(byte_ring_put(&r, 14), 0);
  uint8_t out[4];
  assert_int_equal(byte_ring_read(&r, out, 4), 4);
  assert_memory_equal(out, in, 4);
  assert_int_equal(byte_ring_used(&r), 0);
}

/* Random interleaving of block writes and reads against a reference FIFO. */
static void test_random_traffic_matches_model(void **state)
{
  (void)state;
  uint8_t storage[64];
  byte_ring_t r;
  const byte_ring_cfg_t cfg = {storage, 64u};
  assert_int_equal(byte_ring_init(&r, &cfg), 0);
  uint8_t model[64];
  size_t model_len = 0u;
  uint8_t next = 0u;
  srand(12345u);
  for (int step = 0; step < 20000; ++step) {
    if (rand() % 2 == 0) {
      uint8_t chunk[40];
      const size_t n = (size_t)(rand() % 40);
      for (size_t i = 0; i < n; ++i) chunk[i] = (uint8_t)(next + i);
      const size_t accepted = byte_ring_write(&r, chunk, n);
      const size_t room = 64u - model_len;
      assert_int_equal(accepted, n < room ? n : room);
      for (size_t i = 0; i < accepted; ++i) model[model_len++] = chunk[i];
      next = (uint8_t)(next + accepted);
    } else {
      uint8_t out[40];
      const size_t want = (size_t)(rand() % 40);
      const size_t got = byte_ring_read(&r, out, want);
      assert_int_equal(got, want < model_len ? want : model_len);
      assert_memory_equal(out, model, got);
      for (size_t i = got; i < model_len; ++i) model[i - got] = model[i];
      model_len -= got;
    }
    assert_int_equal(byte_ring_used(&r), model_len);
  }
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_init_validates),
      cmocka_unit_test(test_full_ring_refuses_and_keeps_order),
      cmocka_unit_test(test_counters_wrap_past_2_pow_32),
      cmocka_unit_test(test_random_traffic_matches_model),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
