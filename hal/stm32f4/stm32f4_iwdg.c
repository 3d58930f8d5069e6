#include "stm32f4_iwdg.h"

#include "stm32f4_core.h"
#include "stm32f4_regs.h"

int stm32f4_iwdg_plan(uint32_t lsi_hz, uint32_t timeout_ms, stm32f4_iwdg_plan_t *plan)
{
  if (plan == 0 || lsi_hz == 0u || timeout_ms == 0u) return -1;
  const uint64_t lsi_ticks = (uint64_t)timeout_ms * lsi_hz / 1000u;
  for (uint32_t pr = 0u; pr <= 6u; ++pr) {
    const uint64_t div = 4ull << pr;
    const uint64_t count = (lsi_ticks + div - 1u) / div;
    if (count >= 1u && count <= 4096u) {
      plan->pr = pr;
      plan->rlr = (uint32_t)count - 1u;
      return 0;
    }
  }
  return -1;
}

void stm32f4_iwdg_start(const stm32f4_iwdg_plan_t *plan)
{
  if (plan == 0) return;
  IWDG->KR = IWDG_KEY_START;
  IWDG->KR = IWDG_KEY_ACCESS;
  IWDG->PR = plan->pr;
  IWDG->RLR = plan->rlr;
  /* The new values cross into the LSI domain; bounded wait for the update flags. */
  for (uint32_t i = 0u; i < 100000u && (IWDG->SR & (IWDG_SR_PVU | IWDG_SR_RVU)) != 0u; ++i) {
    STM32F4_POLL_HOOK();
  }
  IWDG->KR = IWDG_KEY_RELOAD;
}

CM4_RAMFUNC void stm32f4_iwdg_kick(void) { IWDG->KR = IWDG_KEY_RELOAD; }
