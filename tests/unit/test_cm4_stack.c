/* Stack high-water mark (hal/cortex_m4/cm4_stack.c): the depth reached by a stack that
 * grows down from the top of a painted region is the distance from the top to the
 * lowest word that no longer holds the paint. Checked against depths written here. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "cm4_stack.h"

#define WORDS 64u

static void paint(uint32_t *w, size_t n)
{
  for (size_t i = 0; i < n; ++i) w[i] = CM4_STACK_PAINT;
}

static void test_untouched_is_zero(void **state)
{
  (void)state;
  uint32_t w[WORDS];
  paint(w, WORDS);
  assert_int_equal(cm4_stack_used_bytes(w, w + WORDS), 0);
}

static void test_depth_of_lowest_write(void **state)
{
  (void)state;
  uint32_t w[WORDS];
  for (size_t depth = 1; depth <= WORDS; ++depth) {
    paint(w, WORDS);
    /* A frame 'depth' words deep: its lowest word is written (zero is a common value),
     * the words above it hold anything, including the paint by chance. */
    w[WORDS - depth] = 0u;
    if (depth > 2) w[WORDS - depth + 1] = CM4_STACK_PAINT;
    assert_int_equal(cm4_stack_used_bytes(w, w + WORDS), 4u * depth);
  }
}

static void test_overflowed_region_is_full(void **state)
{
  (void)state;
  uint32_t w[WORDS];
  paint(w, WORDS);
  w[0] = 0x12345678u;
  assert_int_equal(cm4_stack_used_bytes(w, w + WORDS), 4u * WORDS);
}

static void test_bad_region(void **state)
{
  (void)state;
  uint32_t w[4] = {0u, 0u, 0u, 0u};
  assert_int_equal(cm4_stack_used_bytes(NULL, w + 4), 0);
  assert_int_equal(cm4_stack_used_bytes(w, NULL), 0);
  assert_int_equal(cm4_stack_used_bytes(w + 4, w), 0);
  assert_int_equal(cm4_stack_used_bytes(w, w), 0);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_untouched_is_zero),
      cmocka_unit_test(test_depth_of_lowest_write),
      cmocka_unit_test(test_overflowed_region_is_full),
      cmocka_unit_test(test_bad_region),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
