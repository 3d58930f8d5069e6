/* USART1 driver (hal/stm32f4/stm32f4_uart.c): baud-rate register, interrupt-driven RX
 * and TX rings, driven through a fake USART whose interrupt the test raises by calling
 * the handler with the status flags set. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "hal/hal_uart.h"
#include "stm32f4_host_regs.h"
#include "stm32f4_uart.h"

/* 16x oversampling: baud = f_pclk / (16 * USARTDIV), USARTDIV = mantissa + fraction/16. */
static double actual_baud(uint32_t pclk_hz, uint32_t brr)
{
  const double usartdiv = (double)(brr >> 4) + (double)(brr & 15u) / 16.0;
  return (double)pclk_hz / (16.0 * usartdiv);
}

static void test_brr_values(void **state)
{
  (void)state;
  /* RM0090 table 136 (f_PCLK = 84 MHz, OVER8 = 0): 921.6 kBd -> USARTDIV 5.6875
   * (mantissa 5, fraction 11), error 0.16 %; 115.2 kBd -> 45.5625 (0x2D9). */
  const uint32_t brr = stm32f4_usart_brr(84000000u, 921600u);
  assert_int_equal(brr >> 4, 5);
  assert_int_equal(brr & 15u, 11);
  assert_true(fabs(actual_baud(84000000u, brr) / 921600.0 - 1.0) < 0.002);
  assert_int_equal(stm32f4_usart_brr(84000000u, 115200u), 0x2D9);
  /* From the 16 MHz HSI (clock tree failed) the rate is still within 2.5 %. */
  assert_true(fabs(actual_baud(16000000u, stm32f4_usart_brr(16000000u, 921600u)) / 921600.0 -
                   1.0) < 0.025);
  assert_int_equal(stm32f4_usart_brr(84000000u, 0u), 0);
  assert_int_equal(stm32f4_usart_brr(84000000u, 10000000u), 0); /* USARTDIV < 1 */
  assert_int_equal(stm32f4_usart_brr(84000000u, 100u), 0);      /* BRR > 16 bits */
}

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  assert_int_equal(stm32f4_uart_init(84000000u, 921600u), 0);
  return 0;
}

static void test_init_registers(void **state)
{
  (void)state;
  assert_int_equal(USART1->BRR, 0x5B);
  assert_int_equal(USART1->CR1, USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE);
  assert_true((RCC->APB2ENR & RCC_APB2ENR_USART1EN) != 0u);
  assert_true((NVIC->ISER[37 / 32] & (1u << (37 % 32))) != 0u);
  assert_int_equal(NVIC->IP[37], STM32F4_PRIO_UART << 4);
  assert_int_equal(stm32f4_uart_init(84000000u, 0u), -1);
}

static void receive(uint8_t byte, uint32_t extra_sr)
{
  USART1->SR = USART_SR_RXNE | extra_sr;
  USART1->DR = byte;
  USART1_IRQHandler();
}

static void test_rx_ring_overflow_and_wrap(void **state)
{
  (void)state;
  for (uint32_t i = 0; i < STM32F4_UART_RX_BYTES + 44u; ++i) receive((uint8_t)i, 0u);
  assert_int_equal(stm32f4_uart_rx_dropped(), 44); /* the ring kept the oldest 256 */
  assert_false(hal_uart_rx_lost());                /* bytes before the gap still waiting */
  uint8_t buf[STM32F4_UART_RX_BYTES + 8u];
  assert_int_equal(hal_uart_read(buf, 8u), 8);
  receive(0xEE, 0u); /* room again, but the gap is not yet reached: dropped */
  assert_int_equal(stm32f4_uart_rx_dropped(), 45);
  assert_int_equal(hal_uart_read(&buf[8], sizeof(buf) - 8u), STM32F4_UART_RX_BYTES - 8u);
  for (uint32_t i = 0; i < STM32F4_UART_RX_BYTES; ++i) assert_int_equal(buf[i], (uint8_t)i);
  assert_true(hal_uart_rx_lost()); /* once per loss */
  assert_false(hal_uart_rx_lost());
  /* The indices now wrap across the end of the storage; order is kept. */
  for (uint32_t i = 0; i < 100u; ++i) receive((uint8_t)(200u + i), 0u);
  assert_int_equal(hal_uart_read(buf, 60u), 60);
  for (uint32_t i = 0; i < 60u; ++i) assert_int_equal(buf[i], (uint8_t)(200u + i));
  assert_int_equal(hal_uart_read(buf, sizeof(buf)), 40);
  assert_int_equal(buf[39], (uint8_t)(299u));
  assert_int_equal(hal_uart_read(buf, sizeof(buf)), 0);
  assert_int_equal(hal_uart_read(NULL, 4u), 0);
}

/* An overrun lost the byte before the one in DR: a gap, reported like a full ring. */
static void test_rx_overrun_is_a_gap(void **state)
{
  (void)state;
  receive(0x41, 0u);
  receive(0x42, USART_SR_ORE);
  assert_int_equal(stm32f4_uart_rx_overruns(), 1);
  uint8_t b = 0;
  assert_false(hal_uart_rx_lost());
  assert_int_equal(hal_uart_read(&b, 1u), 1);
  assert_int_equal(b, 0x41);
  assert_true(hal_uart_rx_lost());
  receive(0x43, 0u);
  assert_int_equal(hal_uart_read(&b, 1u), 1);
  assert_int_equal(b, 0x43);
}

static void test_tx_interrupt_drains_ring(void **state)
{
  (void)state;
  const uint8_t msg[] = "stat 123";
  assert_int_equal(hal_uart_tx_free(), STM32F4_UART_TX_BYTES);
  assert_int_equal(hal_uart_write(msg, 8u), 8);
  assert_int_equal(hal_uart_tx_free(), STM32F4_UART_TX_BYTES - 8u);
  assert_true((USART1->CR1 & USART_CR1_TXEIE) != 0u);
  uint8_t sent[8];
  for (int i = 0; i < 8; ++i) {
    USART1->SR = USART_SR_TXE; /* data register empty: the interrupt fires */
    USART1_IRQHandler();
    sent[i] = (uint8_t)USART1->DR;
  }
  assert_memory_equal(sent, msg, 8);
  USART1->SR = USART_SR_TXE;
  USART1_IRQHandler(); /* ring empty: the TXE interrupt is switched off */
  assert_int_equal(USART1->CR1 & USART_CR1_TXEIE, 0);
  assert_int_equal(hal_uart_tx_free(), STM32F4_UART_TX_BYTES);
}

static void test_tx_full_ring_accepts_what_fits(void **state)
{
  (void)state;
  static uint8_t big[STM32F4_UART_TX_BYTES + 100u];
  assert_int_equal(hal_uart_write(big, sizeof(big)), STM32F4_UART_TX_BYTES);
  assert_int_equal(hal_uart_write(big, 1u), 0);
  assert_int_equal(hal_uart_tx_free(), 0);
  assert_int_equal(hal_uart_write(NULL, 3u), 0);
  /* The emulator's pump empties the ring while TXE stays set. */
  USART1->SR = USART_SR_TXE;
  stm32f4_uart_poll_tx();
  assert_int_equal(hal_uart_tx_free(), STM32F4_UART_TX_BYTES);
  assert_int_equal(cm4_host_map.primask, 0); /* interrupts enabled again */
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_brr_values),
      cmocka_unit_test_setup(test_init_registers, setup),
      cmocka_unit_test_setup(test_rx_ring_overflow_and_wrap, setup),
      cmocka_unit_test_setup(test_rx_overrun_is_a_gap, setup),
      cmocka_unit_test_setup(test_tx_interrupt_drains_ring, setup),
      cmocka_unit_test_setup(test_tx_full_ring_accepts_what_fits, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
