#include "app/app_core.h"

#include <stdatomic.h>

bool app_store_dropped(const app_t *a, param_idx_t i)
{
  const unsigned k = (unsigned)i;
  return k < (unsigned)PARAM_COUNT && (a->store_dropped[k / 32u] & (1u << (k % 32u))) != 0u;
}

int app_request(app_t *a, app_req_t r) { return app_request_word(a, (uint32_t)r); }

int app_request_word(app_t *a, uint32_t w)
{
  const uint32_t head = a->req_head;
  if (head - a->req_tail >= APP_REQ_QUEUE) return -1;
  a->req_word[head % APP_REQ_QUEUE] = w;
  atomic_signal_fence(memory_order_release); /* the word before the head that shows it */
  a->req_head = head + 1u;
  return 0;
}

bool app_requests_pending(const app_t *a) { return a->req_head != a->req_tail; }

static gyro_mode_t mode_after(gyro_mode_t m, uint32_t req)
{
  switch ((app_req_t)APP_REQ_KIND(req)) {
  case APP_REQ_DRIVE_ON:
    return (m == GYRO_MODE_ACQUIRE || m == GYRO_MODE_LOCKED) ? m : GYRO_MODE_ACQUIRE;
  case APP_REQ_DRIVE_OFF: return GYRO_MODE_OFF;
  case APP_REQ_SWEEP: return GYRO_MODE_SWEEP;
  case APP_REQ_SWEEP_HANDOVER: return GYRO_MODE_ACQUIRE;
  case APP_REQ_SELFTEST:
  case APP_REQ_CLEAR:
  case APP_REQ_TUNE:
  case APP_REQ_BOARD:
  case APP_REQ_NONE:
  default: return m;
  }
}

/* A request the ISR takes during the walk is applied twice: each one is idempotent. */
gyro_mode_t app_mode_after_queue(const app_t *a)
{
  gyro_mode_t m = a->gyro.sup.mode;
  const uint32_t head = a->req_head;
  for (uint32_t i = a->req_tail; i != head; i++) {
    m = mode_after(m, a->req_word[i % APP_REQ_QUEUE]);
  }
  return m;
}
