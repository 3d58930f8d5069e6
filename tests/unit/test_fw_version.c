#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <cmocka.h>

#include "params/fw_version.h"

/* The string and the packed number must describe the same version. */
static void test_string_matches_number(void **state)
{
  (void)state;
  unsigned maj = 0, min = 0, pat = 0;
  assert_int_equal(sscanf(fw_version_string(), "%u.%u.%u", &maj, &min, &pat), 3);
  assert_int_equal(fw_version_number(), (maj << 16) | (min << 8) | pat);
}

int main(void)
{
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_string_matches_number)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
