/* numparse and numfmt judged against the C library (glibc's strtof/strtod/strtoul and
 * printf are correctly rounded) on hand-picked and generated corpora. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "comm/numfmt.h"
#include "comm/numparse.h"

static uint32_t bits(float f)
{
  uint32_t u;
  memcpy(&u, &f, 4);
  return u;
}

static float from_bits(uint32_t u)
{
  float f;
  memcpy(&f, &u, 4);
  return f;
}

static numparse_status_t parse(const char *s, float *out)
{
  return numparse_f32(s, strlen(s), out);
}

/* What a strictly whole-token, normal-only strtof would say, from glibc. */
typedef struct {
  bool ok;    /* strtof accepted the whole token and the result is normal or zero */
  bool range; /* strtof reported overflow/underflow (or a subnormal) */
  float value;
} ref_t;

static ref_t reference(const char *s)
{
  ref_t r = {false, false, 0.0f};
  char *end = NULL;
  errno = 0;
  const float f = strtof(s, &end);
  if (end != s + strlen(s) || end == s) {
    return r;
  }
  r.value = f;
  if (errno == ERANGE || isinf(f) || (f != 0.0f && fabsf(f) < FLT_MIN)) {
    r.range = true;
  } else {
    r.ok = true;
  }
  return r;
}

static void expect_same_as_strtof(const char *s)
{
  float got = -1.0f;
  const numparse_status_t st = parse(s, &got);
  const ref_t r = reference(s);
  if (r.ok && bits(r.value) == 0x00800000u && st == NUMPARSE_ERR_RANGE) {
    return; /* below FLT_MIN rounded up to it: our policy rejects, glibc may not flag it */
  }
  if (r.ok) {
    if (st != NUMPARSE_OK || bits(got) != bits(r.value)) {
      fail_msg("'%s': got status %d value %a, strtof %a", s, (int)st, (double)got,
               (double)r.value);
    }
  } else if (r.range) {
    if (st != NUMPARSE_ERR_RANGE) {
      fail_msg("'%s': got status %d, strtof out of range", s, (int)st);
    }
  } else if (st == NUMPARSE_OK) {
    fail_msg("'%s': accepted but strtof did not consume it", s);
  }
}

static void test_accept_corpus(void **state)
{
  (void)state;
  const char *ok[] = {
      "0",
      "-0",
      "+0",
      "0.0",
      "000",
      "1",
      "-1",
      "+1.5",
      "1489.9",
      "-99.56",
      ".5",
      "5.",
      "0.03",
      "1e3",
      "1E3",
      "1e+3",
      "1e-3",
      "1.5e-7",
      "12.75",
      "0.1",
      "0.2",
      "0.3",
      "3.14159265358979323846",
      "16777216",
      "16777217",
      "16777218",
      "16777219",
      "33554435",
      "1e10",
      "3.4028234e38",
      "3.40282346638528859811704183484516925440e38",
      "3.4028235677973366e38",
      "1.17549435e-38",
      "1.1754943508222875e-38",
      "1.17549421e-38",
      "9.99999999999999999999e-38",
      "0.000000000000000000000000000000000000011754943508222875",
      "7.038531e-26",
      "0000000000000000000000000000001.0000000000000000000000000000",
      "1.00000005960464477539062500",
      "1.000000059604644775390625",
      "1.0000000596046447753906249",
      "1.0000000596046447753906251",
      "0e99999999",
      "0e-99999999",
      "123456789012345678901234567890",
      "50000",
      "1489.900000000000000001",
  };
  for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
    expect_same_as_strtof(ok[i]);
  }
  float v = 0.0f;
  assert_int_equal(parse("1489.9", &v), NUMPARSE_OK);
  assert_true(v == 1489.9f);
  assert_int_equal(parse("-0", &v), NUMPARSE_OK);
  assert_true(signbit(v) && v == 0.0f);
  /* the float midpoint between 1 and 1 + 2^-23 ties to the even 1 */
  assert_int_equal(parse("1.00000005960464477539062500", &v), NUMPARSE_OK);
  assert_true(v == 1.0f);
}

static void test_reject_corpus(void **state)
{
  (void)state;
  const struct {
    const char *s;
    numparse_status_t st;
  } bad[] = {
      {"abc", NUMPARSE_ERR_SYNTAX},
      {"nan", NUMPARSE_ERR_SYNTAX},
      {"NaN", NUMPARSE_ERR_SYNTAX},
      {"inf", NUMPARSE_ERR_SYNTAX},
      {"-inf", NUMPARSE_ERR_SYNTAX},
      {"infinity", NUMPARSE_ERR_SYNTAX},
      {"1.0x", NUMPARSE_ERR_SYNTAX},
      {" 1", NUMPARSE_ERR_SYNTAX},
      {"1 ", NUMPARSE_ERR_SYNTAX},
      {"0x10", NUMPARSE_ERR_SYNTAX},
      {"0x1p3", NUMPARSE_ERR_SYNTAX},
      {"1e", NUMPARSE_ERR_SYNTAX},
      {"1e+", NUMPARSE_ERR_SYNTAX},
      {".", NUMPARSE_ERR_SYNTAX},
      {"-", NUMPARSE_ERR_SYNTAX},
      {"+", NUMPARSE_ERR_SYNTAX},
      {"1..2", NUMPARSE_ERR_SYNTAX},
      {"1.2.3", NUMPARSE_ERR_SYNTAX},
      {"1e5.5", NUMPARSE_ERR_SYNTAX},
      {"--1", NUMPARSE_ERR_SYNTAX},
      {"+-1", NUMPARSE_ERR_SYNTAX},
      {"1,5", NUMPARSE_ERR_SYNTAX},
      {"e5", NUMPARSE_ERR_SYNTAX},
      {"1e5e5", NUMPARSE_ERR_SYNTAX},
      {"1f", NUMPARSE_ERR_SYNTAX},
      {"\xd9\xa1", NUMPARSE_ERR_SYNTAX},
      {"1\t", NUMPARSE_ERR_SYNTAX},
      {"1e999", NUMPARSE_ERR_RANGE},
      {"-1e999", NUMPARSE_ERR_RANGE},
      {"3.5e38", NUMPARSE_ERR_RANGE},
      {"340282356779733661637539395458142568448",
       NUMPARSE_ERR_RANGE}, /* FLT_MAX/2^128 midpoint: ties to even = 2^128 */
      {"1e-39", NUMPARSE_ERR_RANGE},
      {"1e-50", NUMPARSE_ERR_RANGE},
      {"1e-99999999999", NUMPARSE_ERR_RANGE},
      {"1.1754942e-38", NUMPARSE_ERR_RANGE}, /* rounds to FLT_MIN but is below it */
      {"", NUMPARSE_ERR_EMPTY},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    float v = 42.0f;
    const numparse_status_t st = numparse_f32(bad[i].s, strlen(bad[i].s), &v);
    if (st != bad[i].st) {
      fail_msg("'%s': status %d, want %d", bad[i].s, (int)st, (int)bad[i].st);
    }
    assert_true(v == 42.0f); /* unchanged on error */
  }
  float v = 0.0f;
  assert_int_equal(numparse_f32(NULL, 0u, &v), NUMPARSE_ERR_EMPTY);
  /* length-delimited: a valid prefix of a longer buffer */
  assert_int_equal(numparse_f32("12.5junk", 4u, &v), NUMPARSE_OK);
  assert_true(v == 12.5f);
}

static uint64_t g_rng = 0x9E3779B97F4A7C15ull;
static uint32_t rnd(void)
{
  g_rng ^= g_rng << 13;
  g_rng ^= g_rng >> 7;
  g_rng ^= g_rng << 17;
  return (uint32_t)(g_rng >> 11);
}

/* Random decimal strings of all shapes against strtof. */
static void test_random_decimals(void **state)
{
  (void)state;
  char s[200];
  for (int n = 0; n < 30000; n++) {
    size_t o = 0;
    const uint32_t r = rnd();
    if (r & 1u) {
      s[o++] = (r & 2u) ? '-' : '+';
    }
    const int nd = 1 + (int)(rnd() % ((r & 4u) ? 40u : 12u));
    const int point = (int)(rnd() % (uint32_t)(nd + 2)) - 1; /* -1: no point */
    for (int k = 0; k < nd; k++) {
      if (k == point) {
        s[o++] = '.';
      }
      s[o++] = (char)('0' + rnd() % 10u);
    }
    if (r & 8u) {
      const int e = (int)(rnd() % 100u) - 55;
      o += (size_t)snprintf(s + o, sizeof s - o, "e%d", e);
    }
    s[o] = '\0';
    expect_same_as_strtof(s);
  }
}

/* Exact midpoints between neighbouring floats (ties to even), and a hair either side,
 * including digits far past the 120 kept ones. */
static void test_midpoints(void **state)
{
  (void)state;
  char s[400];
  for (int n = 0; n < 10000; n++) {
    uint32_t b = rnd() & 0x7FFFFFFFu;
    if (b < 0x00800000u || b >= 0x7F7FFFFFu) {
      continue;
    }
    const float f = from_bits(b);
    const float g = from_bits(b + 1u);
    const double mid = ((double)f + (double)g) * 0.5; /* exact: 25 significant bits */
    snprintf(s, sizeof s, "%.130e", mid);             /* exact decimal expansion */
    float v = 0.0f;
    assert_int_equal(parse(s, &v), NUMPARSE_OK);
    assert_int_equal(bits(v), (b & 1u) ? b + 1u : b); /* ties to even */
    expect_same_as_strtof(s);
    /* a 1 far beyond the kept digits tips it up */
    char *e = strchr(s, 'e');
    char tail[16];
    snprintf(tail, sizeof tail, "%s", e);
    snprintf(e, sizeof s - (size_t)(e - s), "%0150d1%s", 0, tail);
    assert_int_equal(parse(s, &v), NUMPARSE_OK);
    assert_int_equal(bits(v), b + 1u);
    expect_same_as_strtof(s);
  }
}

static void test_u32(void **state)
{
  (void)state;
  uint32_t v = 7u;
  assert_int_equal(numparse_u32("0", 1u, &v), NUMPARSE_OK);
  assert_int_equal(v, 0u);
  assert_int_equal(numparse_u32("4294967295", 10u, &v), NUMPARSE_OK);
  assert_int_equal(v, 4294967295u);
  assert_int_equal(numparse_u32("0004294967295", 13u, &v), NUMPARSE_OK);
  v = 7u;
  assert_int_equal(numparse_u32("4294967296", 10u, &v), NUMPARSE_ERR_RANGE);
  assert_int_equal(numparse_u32("99999999999999999999999", 23u, &v), NUMPARSE_ERR_RANGE);
  assert_int_equal(numparse_u32("-1", 2u, &v), NUMPARSE_ERR_SYNTAX);
  assert_int_equal(numparse_u32("+1", 2u, &v), NUMPARSE_ERR_SYNTAX);
  assert_int_equal(numparse_u32("1.0", 3u, &v), NUMPARSE_ERR_SYNTAX);
  assert_int_equal(numparse_u32("1e3", 3u, &v), NUMPARSE_ERR_SYNTAX);
  assert_int_equal(numparse_u32(" 1", 2u, &v), NUMPARSE_ERR_SYNTAX);
  assert_int_equal(numparse_u32("", 0u, &v), NUMPARSE_ERR_EMPTY);
  assert_int_equal(v, 7u);
  char s[32];
  for (int n = 0; n < 30000; n++) {
    const uint64_t x = ((uint64_t)rnd() << 21 ^ rnd()) % 10000000000ull;
    snprintf(s, sizeof s, "%llu", (unsigned long long)x);
    const numparse_status_t st = numparse_u32(s, strlen(s), &v);
    const unsigned long long ref = strtoull(s, NULL, 10);
    if (ref <= 4294967295ull) {
      assert_int_equal(st, NUMPARSE_OK);
      assert_int_equal(v, ref);
    } else {
      assert_int_equal(st, NUMPARSE_ERR_RANGE);
    }
  }
}

/* ---- numfmt ---- */

static int sig_digits(const char *s)
{
  int first = -1, last = -1, i = 0;
  for (const char *p = s; *p && *p != 'e'; p++, i++) {
    if (*p >= '1' && *p <= '9') {
      if (first < 0) {
        first = i;
      }
      last = i;
    }
  }
  int n = 0;
  for (int k = first; k >= 0 && k <= last; k++) {
    n += (s[k] >= '0' && s[k] <= '9') ? 1 : 0;
  }
  return n;
}

/* Shortest digits per the C library: smallest P with strtof("%.{P-1}e") == x. */
static int shortest_ref(float x)
{
  char s[64];
  for (int p = 1; p <= 9; p++) {
    snprintf(s, sizeof s, "%.*e", p - 1, (double)x);
    if (bits(strtof(s, NULL)) == bits(x)) {
      return p;
    }
  }
  return 9;
}

static void test_format_round_trip_shortest(void **state)
{
  (void)state;
  char buf[NUMFMT_F32_MAX];
  for (int n = 0; n < 20000; n++) {
    const uint32_t b = rnd();
    const float x = from_bits(b);
    if (!isnormal(x)) {
      continue;
    }
    const size_t len = numfmt_f32(buf, sizeof buf, x);
    assert_true(len > 0u && len == strlen(buf) && len < NUMFMT_F32_MAX);
    char *end = NULL;
    const float back = strtof(buf, &end);
    if (*end != '\0' || bits(back) != b) {
      fail_msg("%a printed as '%s'", (double)x, buf);
    }
    if (sig_digits(buf) != shortest_ref(x)) {
      fail_msg("%a printed as '%s', %d digits suffice", (double)x, buf, shortest_ref(x));
    }
  }
}

static void test_format_style(void **state)
{
  (void)state;
  const struct {
    float x;
    const char *s;
  } c[] = {
      {1489.9f, "1489.9"},
      {-99.56f, "-99.56"},
      {0.03f, "0.03"},
      {12.75f, "12.75"},
      {100000.0f, "100000"},
      {1e9f, "1000000000"},
      {1e10f, "1e10"},
      {1.5e-7f, "1.5e-7"},
      {0.00001f, "0.00001"},
      {0.000001f, "1e-6"},
      {FLT_MAX, "3.4028235e38"},
      {FLT_MIN, "1.1754944e-38"},
      {0.0f, "0"},
      {-0.0f, "-0"},
      {1.0f, "1"},
      {0.1f, "0.1"},
      {91.0f, "91"},
      {16777216.0f, "16777216"},
  };
  char buf[NUMFMT_F32_MAX];
  for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
    numfmt_f32(buf, sizeof buf, c[i].x);
    assert_string_equal(buf, c[i].s);
  }
  numfmt_f32(buf, sizeof buf, NAN);
  assert_string_equal(buf, "nan");
  numfmt_f32(buf, sizeof buf, -INFINITY);
  assert_string_equal(buf, "-inf");
  assert_int_equal(numfmt_f32(buf, 4u, 1489.9f), 0u); /* too small: empty, no overflow */
  assert_string_equal(buf, "");
  assert_int_equal(numfmt_u32(buf, sizeof buf, 4294967295u), 10u);
  assert_string_equal(buf, "4294967295");
  assert_int_equal(numfmt_u32(buf, sizeof buf, 0u), 1u);
  assert_string_equal(buf, "0");
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_accept_corpus),
      cmocka_unit_test(test_reject_corpus),
      cmocka_unit_test(test_random_decimals),
      cmocka_unit_test(test_midpoints),
      cmocka_unit_test(test_u32),
      cmocka_unit_test(test_format_round_trip_shortest),
      cmocka_unit_test(test_format_style),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
