#include "stm32f4_uart.h"

#include "hal/hal_uart.h"
#include "stm32f4_core.h"
#include "stm32f4_regs.h"
#include "byte_ring.h"

static uint8_t s_rx_storage[STM32F4_UART_RX_BYTES];
static uint8_t s_tx_storage[STM32F4_UART_TX_BYTES];
static byte_ring_t s_rx;
static byte_ring_t s_tx;
static volatile uint32_t s_rx_dropped;
static volatile uint32_t s_rx_overruns;
static volatile uint32_t s_rx_gap; /* set by the ISR on a loss, cleared by the reader */

uint32_t stm32f4_usart_brr(uint32_t pclk_hz, uint32_t baud)
{
  if (baud == 0u) return 0u;
  const uint32_t brr = (uint32_t)(((uint64_t)pclk_hz + baud / 2u) / baud);
  return (brr < 16u || brr > 0xFFFFu) ? 0u : brr;
}

int stm32f4_uart_init(uint32_t pclk_hz, uint32_t baud)
{
  const uint32_t brr = stm32f4_usart_brr(pclk_hz, baud);
  if (brr == 0u) return -1;
  const byte_ring_cfg_t rx_cfg = {s_rx_storage, STM32F4_UART_RX_BYTES};
  const byte_ring_cfg_t tx_cfg = {s_tx_storage, STM32F4_UART_TX_BYTES};
  (void)byte_ring_init(&s_rx, &rx_cfg);
  (void)byte_ring_init(&s_tx, &tx_cfg);
  s_rx_dropped = 0u;
  s_rx_overruns = 0u;
  s_rx_gap = 0u;

  RCC->APB2ENR |= RCC_APB2ENR_USART1EN;
  USART1->CR1 = 0u;
  USART1->CR2 = 0u; /* 1 stop bit */
  USART1->CR3 = 0u; /* no flow control */
  USART1->BRR = brr;
  USART1->CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
  cm4_nvic_enable(STM32F4_IRQ_USART1, STM32F4_PRIO_UART);
  return 0;
}

uint32_t stm32f4_uart_rx_dropped(void) { return s_rx_dropped; }
uint32_t stm32f4_uart_rx_overruns(void) { return s_rx_overruns; }

CM4_RAMFUNC void USART1_IRQHandler(void)
{
  const uint32_t sr = USART1->SR;
  if ((sr & (USART_SR_RXNE | USART_SR_ORE)) != 0u) {
    /* Reading DR after SR clears RXNE and ORE. */
    const uint8_t byte = (uint8_t)(USART1->DR & 0xFFu);
    /* An overrun lost the byte before this one: a gap like a full ring. From a gap on
     * nothing is stored until the reader has reached it (hal_uart_rx_lost). */
    if ((sr & USART_SR_ORE) != 0u) {
      ++s_rx_overruns;
      s_rx_gap = 1u;
    }
    if (s_rx_gap != 0u || !byte_ring_put(&s_rx, byte)) {
      s_rx_gap = 1u;
      ++s_rx_dropped;
    }
  }
  if ((USART1->CR1 & USART_CR1_TXEIE) != 0u && (sr & USART_SR_TXE) != 0u) {
    uint8_t byte;
    if (byte_ring_get(&s_tx, &byte)) {
      USART1->DR = byte;
    } else {
      USART1->CR1 &= ~USART_CR1_TXEIE;
    }
  }
}

void stm32f4_uart_poll_tx(void)
{
  /* One byte per critical section: the ISR (also a consumer of the TX ring) is kept
   * out only for a single hand-over, and the sample interrupt is never held long. */
  for (;;) {
    const uint32_t primask = cm4_get_primask();
    cm4_disable_irq();
    uint8_t byte;
    const int sent = (USART1->SR & USART_SR_TXE) != 0u && byte_ring_get(&s_tx, &byte);
    if (sent) USART1->DR = byte;
    cm4_set_primask(primask);
    if (!sent) break;
  }
}

size_t hal_uart_read(uint8_t *buf, size_t max)
{
  if (buf == 0) return 0u;
  return byte_ring_read(&s_rx, buf, max);
}

bool hal_uart_rx_lost(void)
{
  if (s_rx_gap == 0u || byte_ring_used(&s_rx) != 0u) return false;
  s_rx_gap = 0u; /* a byte the ISR drops meanwhile belongs to the same gap */
  return true;
}

size_t hal_uart_write(const uint8_t *data, size_t len)
{
  if (data == 0 || len == 0u) return 0u;
  const size_t n = byte_ring_write(&s_tx, data, len);
  if (n > 0u) {
    /* A TXE interrupt is pending at once when the data register is already empty. */
    USART1->CR1 |= USART_CR1_TXEIE;
  }
  return n;
}

size_t hal_uart_tx_free(void) { return byte_ring_free(&s_tx); }
