#include "cm4_host_regs.h"

#include <string.h>

static cm4_scb_t s_scb;
static cm4_nvic_t s_nvic;
static cm4_systick_t s_systick;
static cm4_dwt_t s_dwt;
static volatile uint32_t s_cpacr, s_demcr;

cm4_host_map_t cm4_host_map = {&s_scb, &s_nvic, &s_systick, &s_dwt, &s_cpacr, &s_demcr, 0u};

void cm4_host_reset(void)
{
  memset((void *)&s_scb, 0, sizeof s_scb);
  memset((void *)&s_nvic, 0, sizeof s_nvic);
  memset((void *)&s_systick, 0, sizeof s_systick);
  memset((void *)&s_dwt, 0, sizeof s_dwt);
  s_cpacr = 0u;
  s_demcr = 0u;
  cm4_host_map.primask = 0u;
}
