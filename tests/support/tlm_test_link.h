/* A fake UART for telemetry tests: captures every byte the stream writes, with a room
 * limit the test can close and open. Header-only, test code only. */
#ifndef TLM_TEST_LINK_H
#define TLM_TEST_LINK_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#define TLM_TEST_LINK_MAX (4u * 1024u * 1024u)

typedef struct {
  uint8_t *buf; /* TLM_TEST_LINK_MAX bytes, caller-provided */
  size_t len;
  size_t room; /* what room() reports */
  size_t writes;
  size_t oversize; /* writes beyond room (must stay 0) */
} tlm_test_link_t;

static inline size_t tlm_test_room(void *ctx)
{
  const tlm_test_link_t *l = ctx;
  const size_t left = TLM_TEST_LINK_MAX - l->len;
  return (l->room < left) ? l->room : left;
}

static inline void tlm_test_write(void *ctx, const uint8_t *data, size_t n)
{
  tlm_test_link_t *l = ctx;
  if (n > tlm_test_room(ctx)) {
    l->oversize++;
    return;
  }
  memcpy(&l->buf[l->len], data, n);
  l->len += n;
  l->writes++;
}

#endif /* TLM_TEST_LINK_H */
