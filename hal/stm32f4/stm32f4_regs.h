/* STM32F405 register map: only the peripherals and bits this port uses (the Cortex-M4
 * core's registers are in hal/cortex_m4/cm4_regs.h, included here).
 * Addresses and bit positions from RM0090 (STM32F405/415/407/417 reference manual):
 * memory map §2.3 table 1, RCC §7.3, PWR §5.4, FLASH §3.8, GPIO §8.4, TIM1/TIM8 §17.4,
 * TIM2-TIM5 §18.4, SPI §28.5, DMA §10.5, USART §30.6, IWDG §21.4, I2C §27.6.
 *
 * Host builds (STM32F4_HOST_TEST defined) see every peripheral through a pointer in
 * stm32f4_host_map, which a unit test points at RAM structs: the drivers then run their
 * real register sequences against a fake register file. Busy-wait loops call
 * STM32F4_POLL_HOOK() so that a test can play the hardware's part (set a ready flag,
 * snapshot a control register at the moment the driver waits for it).
 *
 * Registers whose access itself has an effect in hardware (the I2C's: reading SR2 or DR,
 * writing DR or CR1 clears or raises status flags, RM0090 §27.6.6-27.6.7) are accessed
 * with STM32F4_RD / STM32F4_WR: plain accesses on the target; on the host the access
 * calls access_hook afterwards, so that a test can play the peripheral's answer. */
#ifndef STM32F4_REGS_H
#define STM32F4_REGS_H

#include <stdint.h>

#include "cm4_regs.h"

#define STM32F4_REG volatile uint32_t

typedef struct {
  STM32F4_REG CR, PLLCFGR, CFGR, CIR, AHB1RSTR, AHB2RSTR, AHB3RSTR, RES0;
  STM32F4_REG APB1RSTR, APB2RSTR, RES1[2];
  STM32F4_REG AHB1ENR, AHB2ENR, AHB3ENR, RES2, APB1ENR, APB2ENR, RES3[2];
  STM32F4_REG AHB1LPENR, AHB2LPENR, AHB3LPENR, RES4, APB1LPENR, APB2LPENR, RES5[2];
  STM32F4_REG BDCR, CSR, RES6[2], SSCGR, PLLI2SCFGR;
} stm32f4_rcc_t;

typedef struct {
  STM32F4_REG CR, CSR;
} stm32f4_pwr_t;

typedef struct {
  STM32F4_REG ACR, KEYR, OPTKEYR, SR, CR, OPTCR;
} stm32f4_flash_t;

typedef struct {
  STM32F4_REG MODER, OTYPER, OSPEEDR, PUPDR, IDR, ODR, BSRR, LCKR, AFR[2];
} stm32f4_gpio_t;

typedef struct {
  STM32F4_REG CR1, CR2, SMCR, DIER, SR, EGR, CCMR1, CCMR2, CCER, CNT, PSC, ARR, RCR;
  STM32F4_REG CCR1, CCR2, CCR3, CCR4, BDTR, DCR, DMAR, OR;
} stm32f4_tim_t;

typedef struct {
  STM32F4_REG CR1, CR2, SR, DR, CRCPR, RXCRCR, TXCRCR, I2SCFGR, I2SPR;
} stm32f4_spi_t;

typedef struct {
  STM32F4_REG CR, NDTR, PAR, M0AR, M1AR, FCR;
} stm32f4_dma_stream_t;

typedef struct {
  STM32F4_REG LISR, HISR, LIFCR, HIFCR;
  stm32f4_dma_stream_t S[8];
} stm32f4_dma_t;

typedef struct {
  STM32F4_REG SR, DR, BRR, CR1, CR2, CR3, GTPR;
} stm32f4_usart_t;

typedef struct {
  STM32F4_REG KR, PR, RLR, SR;
} stm32f4_iwdg_t;

typedef struct {
  STM32F4_REG CR1, CR2, OAR1, OAR2, DR, SR1, SR2, CCR, TRISE, FLTR;
} stm32f4_i2c_t;

/* Base addresses (RM0090 table 1; ARMv7-M system address map). */
#define STM32F4_TIM2_BASE 0x40000000UL
#define STM32F4_TIM4_BASE 0x40000800UL
#define STM32F4_PWR_BASE 0x40007000UL
#define STM32F4_IWDG_BASE 0x40003000UL
#define STM32F4_SPI2_BASE 0x40003800UL
#define STM32F4_SPI3_BASE 0x40003C00UL
#define STM32F4_I2C1_BASE 0x40005400UL
#define STM32F4_TIM1_BASE 0x40010000UL
#define STM32F4_TIM8_BASE 0x40010400UL
#define STM32F4_USART1_BASE 0x40011000UL
#define STM32F4_SPI1_BASE 0x40013000UL
#define STM32F4_GPIOA_BASE 0x40020000UL
#define STM32F4_GPIOB_BASE 0x40020400UL
#define STM32F4_GPIOC_BASE 0x40020800UL
#define STM32F4_RCC_BASE 0x40023800UL
#define STM32F4_FLASH_R_BASE 0x40023C00UL
#define STM32F4_DMA2_BASE 0x40026400UL

/* Flash sectors 1 and 2 (16 KB each) hold the A/B parameter store (RM0090 table 5). */
#define STM32F4_PARAM_FLASH_ADDR 0x08004000UL
#define STM32F4_PARAM_SECTOR_FIRST 1u
#define STM32F4_PARAM_NUM_SECTORS 2u
#define STM32F4_PARAM_SECTOR_BYTES 16384u

#ifdef STM32F4_HOST_TEST
typedef struct {
  stm32f4_rcc_t *rcc;
  stm32f4_pwr_t *pwr;
  stm32f4_flash_t *flash;
  stm32f4_gpio_t *gpioa, *gpiob, *gpioc;
  stm32f4_tim_t *tim1, *tim2, *tim4, *tim8;
  stm32f4_spi_t *spi1, *spi2, *spi3;
  stm32f4_dma_t *dma2;
  stm32f4_usart_t *usart1;
  stm32f4_iwdg_t *iwdg;
  stm32f4_i2c_t *i2c1;
  volatile uint8_t *param_flash; /* STM32F4_PARAM_NUM_SECTORS * SECTOR_BYTES bytes */
  void (*poll_hook)(void);       /* the "hardware": called from every busy-wait loop */
  /* the "hardware" of registers accessed with STM32F4_RD/WR: called after the access */
  void (*access_hook)(volatile uint32_t *reg, int is_write, uint32_t value);
} stm32f4_host_map_t;
extern stm32f4_host_map_t stm32f4_host_map;
static inline uint32_t stm32f4_host_rd(volatile uint32_t *reg)
{
  const uint32_t v = *reg;
  if (stm32f4_host_map.access_hook != 0) stm32f4_host_map.access_hook(reg, 0, v);
  return v;
}
static inline void stm32f4_host_wr(volatile uint32_t *reg, uint32_t v)
{
  *reg = v;
  if (stm32f4_host_map.access_hook != 0) stm32f4_host_map.access_hook(reg, 1, v);
}
#define STM32F4_RD(reg) stm32f4_host_rd(&(reg))
#define STM32F4_WR(reg, v) stm32f4_host_wr(&(reg), (v))
#define STM32F4_PERIPH(field, type, addr) (stm32f4_host_map.field)
#define STM32F4_PARAM_FLASH ((volatile uint8_t *)stm32f4_host_map.param_flash)
#define STM32F4_POLL_HOOK() \
  do { \
    if (stm32f4_host_map.poll_hook != 0) stm32f4_host_map.poll_hook(); \
  } while (0)
#else
#define STM32F4_PERIPH(field, type, addr) ((type *)(addr))
#define STM32F4_PARAM_FLASH ((volatile uint8_t *)STM32F4_PARAM_FLASH_ADDR)
#define STM32F4_POLL_HOOK() ((void)0)
#define STM32F4_RD(reg) (reg)
#define STM32F4_WR(reg, v) ((reg) = (v))
#endif

#define RCC STM32F4_PERIPH(rcc, stm32f4_rcc_t, STM32F4_RCC_BASE)
#define PWR STM32F4_PERIPH(pwr, stm32f4_pwr_t, STM32F4_PWR_BASE)
#define FLASH_R STM32F4_PERIPH(flash, stm32f4_flash_t, STM32F4_FLASH_R_BASE)
#if defined(STM32F4_QEMU_FLASH_MODEL) && !defined(STM32F4_HOST_TEST)
/* gyro-fw-qemu: QEMU's netduinoplus2 models neither the flash interface nor writable
 * flash, so the emulator image runs the board's flash driver unchanged against a model
 * of both in SRAM (qemu/stm32f4_qemu_flash.c), which plays the controller from the
 * driver's busy-wait hook as the unit test's fake does. */
#undef FLASH_R
#undef STM32F4_PARAM_FLASH
#undef STM32F4_POLL_HOOK
extern stm32f4_flash_t stm32f4_qemu_flash_regs;
extern volatile uint8_t stm32f4_qemu_param_flash[];
void stm32f4_qemu_flash_controller(void);
#define FLASH_R (&stm32f4_qemu_flash_regs)
#define STM32F4_PARAM_FLASH (stm32f4_qemu_param_flash)
#define STM32F4_POLL_HOOK() stm32f4_qemu_flash_controller()
#endif
#define GPIOA STM32F4_PERIPH(gpioa, stm32f4_gpio_t, STM32F4_GPIOA_BASE)
#define GPIOB STM32F4_PERIPH(gpiob, stm32f4_gpio_t, STM32F4_GPIOB_BASE)
#define GPIOC STM32F4_PERIPH(gpioc, stm32f4_gpio_t, STM32F4_GPIOC_BASE)
#define TIM1 STM32F4_PERIPH(tim1, stm32f4_tim_t, STM32F4_TIM1_BASE)
#define TIM2 STM32F4_PERIPH(tim2, stm32f4_tim_t, STM32F4_TIM2_BASE)
#define TIM4 STM32F4_PERIPH(tim4, stm32f4_tim_t, STM32F4_TIM4_BASE)
#define TIM8 STM32F4_PERIPH(tim8, stm32f4_tim_t, STM32F4_TIM8_BASE)
#define SPI1 STM32F4_PERIPH(spi1, stm32f4_spi_t, STM32F4_SPI1_BASE)
#define SPI2 STM32F4_PERIPH(spi2, stm32f4_spi_t, STM32F4_SPI2_BASE)
#define SPI3 STM32F4_PERIPH(spi3, stm32f4_spi_t, STM32F4_SPI3_BASE)
#define DMA2 STM32F4_PERIPH(dma2, stm32f4_dma_t, STM32F4_DMA2_BASE)
#define USART1 STM32F4_PERIPH(usart1, stm32f4_usart_t, STM32F4_USART1_BASE)
#define IWDG STM32F4_PERIPH(iwdg, stm32f4_iwdg_t, STM32F4_IWDG_BASE)
#define I2C1 STM32F4_PERIPH(i2c1, stm32f4_i2c_t, STM32F4_I2C1_BASE)

/* ---- RCC (RM0090 §7.3) ---- */
#define RCC_CR_HSION (1u << 0)
#define RCC_CR_HSIRDY (1u << 1)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_CSSON (1u << 19)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_PLLCFGR_PLLM_POS 0u
#define RCC_PLLCFGR_PLLN_POS 6u
#define RCC_PLLCFGR_PLLP_POS 16u /* 00: /2, 01: /4, 10: /6, 11: /8 */
#define RCC_PLLCFGR_PLLSRC_HSE (1u << 22)
#define RCC_PLLCFGR_PLLQ_POS 24u
#define RCC_CFGR_SW_MASK 3u
#define RCC_CFGR_SW_PLL 2u
#define RCC_CFGR_SWS_POS 2u
#define RCC_CFGR_HPRE_POS 4u   /* 0xxx: /1 */
#define RCC_CFGR_PPRE1_POS 10u /* 0xx: /1, 100: /2, 101: /4, 110: /8, 111: /16 */
#define RCC_CFGR_PPRE2_POS 13u
#define RCC_CSR_LSION (1u << 0)
#define RCC_CSR_LSIRDY (1u << 1)
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_PINRSTF (1u << 26)
#define RCC_CSR_PORRSTF (1u << 27)
#define RCC_CSR_SFTRSTF (1u << 28)
#define RCC_CSR_IWDGRSTF (1u << 29)
#define RCC_AHB1ENR_GPIOAEN (1u << 0)
#define RCC_AHB1ENR_GPIOBEN (1u << 1)
#define RCC_AHB1ENR_GPIOCEN (1u << 2)
#define RCC_AHB1ENR_CCMDATARAMEN (1u << 20)
#define RCC_AHB1ENR_DMA2EN (1u << 22)
#define RCC_APB1ENR_TIM2EN (1u << 0)
#define RCC_APB1ENR_TIM4EN (1u << 2)
#define RCC_APB1ENR_SPI2EN (1u << 14)
#define RCC_APB1ENR_SPI3EN (1u << 15)
#define RCC_APB1ENR_I2C1EN (1u << 21)
#define RCC_APB1ENR_PWREN (1u << 28)
#define RCC_APB2ENR_TIM1EN (1u << 0)
#define RCC_APB2ENR_TIM8EN (1u << 1)
#define RCC_APB2ENR_USART1EN (1u << 4)
#define RCC_APB2ENR_SPI1EN (1u << 12)

/* ---- PWR (RM0090 §5.4.1): VOS = 1 selects scale 1, needed for 168 MHz ---- */
#define PWR_CR_VOS (1u << 14)

/* ---- FLASH interface (RM0090 §3.8) ---- */
#define FLASH_ACR_LATENCY_MASK 7u
#define FLASH_ACR_PRFTEN (1u << 8)
#define FLASH_ACR_ICEN (1u << 9)
#define FLASH_ACR_DCEN (1u << 10)
#define FLASH_ACR_ICRST (1u << 11)
#define FLASH_ACR_DCRST (1u << 12)
#define FLASH_KEY1 0x45670123u
#define FLASH_KEY2 0xCDEF89ABu
#define FLASH_SR_EOP (1u << 0)
#define FLASH_SR_OPERR (1u << 1)
#define FLASH_SR_WRPERR (1u << 4)
#define FLASH_SR_PGAERR (1u << 5)
#define FLASH_SR_PGPERR (1u << 6)
#define FLASH_SR_PGSERR (1u << 7)
#define FLASH_SR_BSY (1u << 16)
#define FLASH_SR_ERRORS \
  (FLASH_SR_OPERR | FLASH_SR_WRPERR | FLASH_SR_PGAERR | FLASH_SR_PGPERR | FLASH_SR_PGSERR)
#define FLASH_CR_PG (1u << 0)
#define FLASH_CR_SER (1u << 1)
#define FLASH_CR_SNB_POS 3u
#define FLASH_CR_SNB_MASK (0xFu << 3)
#define FLASH_CR_PSIZE_X8 (0u << 8)
#define FLASH_CR_PSIZE_X32 (2u << 8)
#define FLASH_CR_PSIZE_MASK (3u << 8)
#define FLASH_CR_STRT (1u << 16)
#define FLASH_CR_LOCK (1u << 31)

/* ---- GPIO (RM0090 §8.4) ---- */
#define GPIO_MODE_INPUT 0u
#define GPIO_MODE_OUTPUT 1u
#define GPIO_MODE_AF 2u
#define GPIO_SPEED_HIGH 2u
#define GPIO_SPEED_VERY_HIGH 3u

/* ---- TIM1/TIM8 (RM0090 §17.4) ---- */
#define TIM_CR1_CEN (1u << 0)
#define TIM_CR1_URS (1u << 2)
#define TIM_CR1_OPM (1u << 3)
#define TIM_CR1_ARPE (1u << 7)
#define TIM_DIER_CC1DE (1u << 9)
#define TIM_DIER_CC2DE (1u << 10)
#define TIM_DIER_CC3DE (1u << 11)
#define TIM_DIER_CC4DE (1u << 12)
#define TIM_EGR_UG (1u << 0)
/* Master/slave (RM0090 §17.4.2-3, §18.4.2-3): CR2.MMS picks what drives TRGO; SMCR.TS
 * picks the trigger input, SMCR.SMS what the trigger does. */
#define TIM_CR2_MMS_POS 4u
#define TIM_MMS_UPDATE 2u /* TRGO = update event */
#define TIM_MMS_OC1REF 4u /* TRGO = OC1REF */
#define TIM_SMCR_TS_POS 4u
#define TIM_TS_ITR0 0u     /* TIM4's ITR0 = TIM1 TRGO (TIM2-TIM5 internal trigger table) */
#define TIM_TS_ITR2 2u     /* TIM8's ITR2 = TIM4 TRGO (TIM1/TIM8 internal trigger table) */
#define TIM_SMS_RESET 4u   /* a trigger edge resets the counter */
#define TIM_SMS_TRIGGER 6u /* a trigger edge sets CEN */
#define TIM_OCM_PWM1 6u    /* active while CNT < CCR */
#define TIM_OCM_PWM2 7u    /* inactive while CNT < CCR */
#define TIM_CCMR_OC1M_POS 4u
#define TIM_CCMR_OC1PE (1u << 3)
#define TIM_CCMR_OC2M_POS 12u
#define TIM_CCMR_OC2PE (1u << 11)
#define TIM_CCMR_OC4M_POS 12u /* in CCMR2 */
#define TIM_CCMR_OC4PE (1u << 11)
#define TIM_CCER_CC1E (1u << 0)
#define TIM_CCER_CC1P (1u << 1)
#define TIM_CCER_CC2E (1u << 4)
#define TIM_CCER_CC2P (1u << 5)
#define TIM_CCER_CC3E (1u << 8)
#define TIM_CCER_CC3P (1u << 9)
#define TIM_BDTR_MOE (1u << 15)

/* ---- SPI (RM0090 §28.5) ---- */
#define SPI_CR1_CPHA (1u << 0)
#define SPI_CR1_CPOL (1u << 1)
#define SPI_CR1_MSTR (1u << 2)
#define SPI_CR1_BR_POS 3u /* fPCLK / 2^(BR+1) */
#define SPI_CR1_SPE (1u << 6)
#define SPI_CR1_SSI (1u << 8)
#define SPI_CR1_SSM (1u << 9)
#define SPI_CR1_DFF (1u << 11)
#define SPI_CR1_BIDIOE (1u << 14)
#define SPI_CR1_BIDIMODE (1u << 15)
#define SPI_CR2_RXDMAEN (1u << 0)
#define SPI_CR2_TXDMAEN (1u << 1)
#define SPI_SR_RXNE (1u << 0)
#define SPI_SR_TXE (1u << 1)
#define SPI_SR_OVR (1u << 6)
#define SPI_SR_BSY (1u << 7)

/* ---- DMA (RM0090 §10.5) ---- */
#define DMA_SXCR_EN (1u << 0)
#define DMA_SXCR_TEIE (1u << 2)
#define DMA_SXCR_TCIE (1u << 4)
#define DMA_SXCR_DIR_P2M (0u << 6)
#define DMA_SXCR_DIR_M2P (1u << 6)
#define DMA_SXCR_CIRC (1u << 8)
#define DMA_SXCR_MINC (1u << 10)
#define DMA_SXCR_PSIZE_16 (1u << 11)
#define DMA_SXCR_MSIZE_16 (1u << 13)
#define DMA_SXCR_PL_HIGH (2u << 16)
#define DMA_SXCR_PL_VERY_HIGH (3u << 16)
#define DMA_SXCR_CHSEL_POS 25u
/* Interrupt flags of one stream, before shifting to its place in LISR/HISR. */
#define DMA_FLAG_FEIF 0x01u
#define DMA_FLAG_DMEIF 0x04u
#define DMA_FLAG_TEIF 0x08u
#define DMA_FLAG_HTIF 0x10u
#define DMA_FLAG_TCIF 0x20u
#define DMA_FLAG_ALL 0x3Du

/* ---- USART (RM0090 §30.6) ---- */
#define USART_SR_ORE (1u << 3)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TC (1u << 6)
#define USART_SR_TXE (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_TXEIE (1u << 7)
#define USART_CR1_UE (1u << 13)

/* ---- I2C (RM0090 §27.6; the F4's I2C v1) ---- */
#define I2C_CR1_PE (1u << 0)
#define I2C_CR1_START (1u << 8)
#define I2C_CR1_STOP (1u << 9)
#define I2C_CR1_ACK (1u << 10)
#define I2C_CR1_POS (1u << 11)
#define I2C_CR1_SWRST (1u << 15)
#define I2C_CR2_FREQ_MASK 0x3Fu /* PCLK1 in MHz, 2..42 */
#define I2C_SR1_SB (1u << 0)
#define I2C_SR1_ADDR (1u << 1)
#define I2C_SR1_BTF (1u << 2)
#define I2C_SR1_STOPF (1u << 4)
#define I2C_SR1_RXNE (1u << 6)
#define I2C_SR1_TXE (1u << 7)
#define I2C_SR1_BERR (1u << 8)
#define I2C_SR1_ARLO (1u << 9)
#define I2C_SR1_AF (1u << 10)
#define I2C_SR1_OVR (1u << 11)
#define I2C_SR2_MSL (1u << 0)
#define I2C_SR2_BUSY (1u << 1)
#define I2C_CCR_MASK 0xFFFu
#define I2C_CCR_DUTY (1u << 14) /* fast mode: 0 = Tlow/Thigh 2, 1 = 16/9 */
#define I2C_CCR_FS (1u << 15)   /* fast mode (up to 400 kHz) */
#define I2C_TRISE_MASK 0x3Fu

/* ---- IWDG (RM0090 §21.4) ---- */
#define IWDG_KEY_RELOAD 0xAAAAu
#define IWDG_KEY_ACCESS 0x5555u
#define IWDG_KEY_START 0xCCCCu
#define IWDG_SR_PVU (1u << 0)
#define IWDG_SR_RVU (1u << 1)

/* STM32F405 interrupt numbers (RM0090 table 61) used by this port. */
enum stm32f4_irq {
  STM32F4_IRQ_USART1 = 37,
  STM32F4_IRQ_DMA2_STREAM0 = 56,
  STM32F4_NUM_IRQS = 82
};

/* NVIC priorities (cm4_nvic_enable): 4 implemented bits on the STM32F4 (RM0090 §12.1). */
#define STM32F4_PRIO_SAMPLE 0u /* the 50 kHz sample interrupt: nothing preempts it */
#define STM32F4_PRIO_UART 8u   /* tuning port: preempted by the sample interrupt */

/* Bit offset of stream n's flags inside LISR/HISR (streams n and n+4 share an offset). */
static inline uint32_t stm32f4_dma_flag_shift(uint32_t stream)
{
  return ((stream & 2u) != 0u ? 16u : 0u) + ((stream & 1u) != 0u ? 6u : 0u);
}

static inline uint32_t stm32f4_dma_flags(const stm32f4_dma_t *dma, uint32_t stream)
{
  const uint32_t isr = (stream < 4u) ? dma->LISR : dma->HISR;
  return (isr >> stm32f4_dma_flag_shift(stream)) & DMA_FLAG_ALL;
}

static inline void stm32f4_dma_clear(stm32f4_dma_t *dma, uint32_t stream, uint32_t flags)
{
  const uint32_t v = (flags & DMA_FLAG_ALL) << stm32f4_dma_flag_shift(stream);
  if (stream < 4u) {
    dma->LIFCR = v;
  } else {
    dma->HIFCR = v;
  }
}

#endif /* STM32F4_REGS_H */
