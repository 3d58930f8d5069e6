#include "stm32f4_i2c.h"

#include "stm32f4_core.h"

/* The transfer's steps; each waits for one status flag (RM0090 §27.3.3, master mode). */
enum {
  ST_IDLE = 0,
  ST_WAIT_FREE, /* the last STOP not yet on the bus, or another master holds it */
  ST_START,     /* START (or repeated START) requested: wait for SB */
  ST_ADDR,      /* address sent: wait for ADDR (or AF: nobody answered) */
  ST_TX,        /* write: TXE for each byte, then BTF for the last one */
  ST_RX         /* read: RXNE (1 byte) or BTF (2 bytes) */
};

#define I2C_SR1_ERRORS (I2C_SR1_BERR | I2C_SR1_ARLO | I2C_SR1_AF | I2C_SR1_OVR)
#define MHZ 1000000u
#define SM_RISE_NS 1000u /* I2C-bus spec, as RM0090 §27.6.9 quotes it */
#define FM_RISE_NS 300u

int stm32f4_i2c_timing(uint32_t pclk1_hz, uint32_t scl_hz, stm32f4_i2c_timing_t *t)
{
  if (t == 0 || scl_hz == 0u || scl_hz > 400000u) return -1;
  const uint32_t freq_mhz = pclk1_hz / MHZ;
  const int fast = scl_hz > 100000u;
  /* CR2.FREQ 2..42 MHz; fast mode needs PCLK1 >= 4 MHz (RM0090 §27.6.2). */
  if (freq_mhz < (fast ? 4u : 2u) || freq_mhz > 42u) return -1;
  /* §27.6.8: standard mode Thigh = Tlow = CCR x T_PCLK1, so f_SCL = PCLK1 / (2 CCR),
   * CCR >= 4; fast mode with DUTY 0: Thigh = CCR x T_PCLK1, Tlow = 2 CCR x T_PCLK1, so
   * f_SCL = PCLK1 / (3 CCR), CCR >= 1. DUTY 1 (16/9) would need PCLK1 a multiple of
   * 10 MHz for 400 kHz; at 42 MHz, DUTY 0 gives CCR 35 and exactly 400 kHz, with
   * Tlow 1.67 us and Thigh 0.83 us (the bus spec's minima: 1.3 and 0.6 us). */
  const uint32_t div = fast ? 3u * scl_hz : 2u * scl_hz;
  const uint32_t ccr = (pclk1_hz + div - 1u) / div;
  if (ccr < (fast ? 1u : 4u) || ccr > I2C_CCR_MASK) return -1;
  t->cr2_freq = freq_mhz;
  t->ccr = ccr | (fast ? I2C_CCR_FS : 0u);
  /* §27.6.9: TRISE = the longest SCL rise in PCLK1 periods + 1: 300 ns x 42 MHz = 12.6,
   * so 12 + 1 = 13 in fast mode. */
  t->trise = (freq_mhz * (fast ? FM_RISE_NS : SM_RISE_NS)) / 1000u + 1u;
  return 0;
}

/* Software reset (CR1.SWRST: every register back to its reset value, the lines released)
 * and the master set-up again; the peripheral's clock registers are written with PE 0
 * (§27.6.8: CCR only while the peripheral is disabled). */
static void reset_and_program(stm32f4_i2c_master_t *m)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  STM32F4_WR(r->CR1, I2C_CR1_SWRST);
  STM32F4_WR(r->CR1, 0u);
  STM32F4_WR(r->CR2, m->timing.cr2_freq);
  STM32F4_WR(r->CCR, m->timing.ccr);
  STM32F4_WR(r->TRISE, m->timing.trise);
  STM32F4_WR(r->CR1, I2C_CR1_PE);
  m->state = ST_IDLE;
}

int stm32f4_i2c_init(stm32f4_i2c_master_t *m, const stm32f4_i2c_config_t *cfg)
{
  if (m == 0 || cfg == 0 || cfg->regs == 0) return -1;
  m->cfg = *cfg;
  m->state = ST_IDLE;
  m->resets = 0u;
  if (stm32f4_i2c_timing(cfg->pclk1_hz, cfg->scl_hz, &m->timing) != 0) return -1;
  RCC->APB1ENR |= cfg->rcc_apb1enr_bit;
  reset_and_program(m);
  return 0;
}

int stm32f4_i2c_begin(stm32f4_i2c_master_t *m, uint8_t addr7, const uint8_t *tx,
                      uint32_t tx_len, uint32_t rx_len, uint32_t now_cycles)
{
  if (m == 0 || m->state != ST_IDLE || m->cfg.regs == 0) return -1;
  if (tx_len > STM32F4_I2C_TX_MAX || rx_len > STM32F4_I2C_RX_MAX) return -1;
  if ((tx_len == 0u && rx_len == 0u) || (tx_len != 0u && tx == 0) || addr7 > 0x7Fu) return -1;
  for (uint32_t i = 0u; i < tx_len; ++i) m->tx[i] = tx[i];
  m->addr7 = addr7;
  m->tx_len = (uint8_t)tx_len;
  m->tx_done = 0u;
  m->rx_len = (uint8_t)rx_len;
  m->t_begin = now_cycles;
  m->state = ST_WAIT_FREE;
  return 0;
}

static stm32f4_i2c_status_t fail(stm32f4_i2c_master_t *m, stm32f4_i2c_status_t why)
{
  reset_and_program(m);
  ++m->resets;
  return why;
}

static stm32f4_i2c_status_t finish(stm32f4_i2c_master_t *m)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  /* POS stays set until software clears it (§27.6.1); the next read sets what it needs. */
  STM32F4_WR(r->CR1, STM32F4_RD(r->CR1) & ~(I2C_CR1_POS | I2C_CR1_ACK));
  m->state = ST_IDLE;
  return STM32F4_I2C_DONE;
}

static void request(stm32f4_i2c_t *r, uint32_t cr1_bit)
{
  STM32F4_WR(r->CR1, STM32F4_RD(r->CR1) | cr1_bit);
}

/* SB: the (repeated) START is on the bus. Reading SR1 (done by the caller) and writing
 * the address into DR clears SB (§27.6.6). A read of 2 bytes sets POS and ACK before
 * the address goes out (§27.3.3, Method 2 for N = 2); a read of 1 byte clears ACK at
 * the ADDR event instead. */
static void on_start(stm32f4_i2c_master_t *m)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  const int reading = m->tx_done == m->tx_len;
  if (reading) {
    const uint32_t cr1 = STM32F4_RD(r->CR1) & ~(I2C_CR1_POS | I2C_CR1_ACK);
    STM32F4_WR(r->CR1, cr1 | (m->rx_len == 2u ? (I2C_CR1_POS | I2C_CR1_ACK) : 0u));
  }
  STM32F4_WR(r->DR, ((uint32_t)m->addr7 << 1) | (reading ? 1u : 0u));
  m->state = ST_ADDR;
}

/* ADDR: the address was acknowledged; reading SR2 after SR1 clears it (§27.6.7) and
 * releases the clock. For a read, §27.3.3 Method 2: N = 1, ACK cleared before ADDR and
 * STOP programmed right after it; N = 2, ACK cleared right after ADDR (with POS set it
 * NACKs the second byte). Done with interrupts off so that the sample interrupt cannot
 * come between the two (the byte under way takes 22.5 us at 400 kHz; the interrupt is
 * far shorter, but the order must hold whatever runs). */
static void on_addr(stm32f4_i2c_master_t *m)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  if (m->tx_done < m->tx_len) {
    (void)STM32F4_RD(r->SR2);
    m->state = ST_TX;
    return;
  }
  const uint32_t primask = cm4_get_primask();
  cm4_disable_irq();
  if (m->rx_len == 1u) {
    STM32F4_WR(r->CR1, STM32F4_RD(r->CR1) & ~I2C_CR1_ACK);
    (void)STM32F4_RD(r->SR2);
    request(r, I2C_CR1_STOP);
  } else {
    (void)STM32F4_RD(r->SR2);
    STM32F4_WR(r->CR1, STM32F4_RD(r->CR1) & ~I2C_CR1_ACK);
  }
  cm4_set_primask(primask);
  m->state = ST_RX;
}

/* Write: one byte per TXE; after the last, BTF (it has left the shift register and
 * was acknowledged), then a repeated START for the read, or the STOP. */
static stm32f4_i2c_status_t on_tx(stm32f4_i2c_master_t *m, uint32_t sr1)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  if (m->tx_done < m->tx_len) {
    if ((sr1 & I2C_SR1_TXE) != 0u) STM32F4_WR(r->DR, m->tx[m->tx_done++]);
    return STM32F4_I2C_BUSY;
  }
  if ((sr1 & I2C_SR1_BTF) == 0u) return STM32F4_I2C_BUSY;
  if (m->rx_len == 0u) {
    request(r, I2C_CR1_STOP);
    return finish(m);
  }
  request(r, I2C_CR1_START);
  m->state = ST_START;
  return STM32F4_I2C_BUSY;
}

/* Read: N = 1, the byte on RXNE (the STOP is already programmed); N = 2, wait for BTF
 * (byte 1 in DR, byte 2 in the shift register, the clock stretched), program STOP,
 * then read DR twice (§27.3.3 Method 2). */
static stm32f4_i2c_status_t on_rx(stm32f4_i2c_master_t *m, uint32_t sr1)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  if (m->rx_len == 1u) {
    if ((sr1 & I2C_SR1_RXNE) == 0u) return STM32F4_I2C_BUSY;
    m->rx[0] = (uint8_t)(STM32F4_RD(r->DR) & 0xFFu);
    return finish(m);
  }
  if ((sr1 & I2C_SR1_BTF) == 0u) return STM32F4_I2C_BUSY;
  request(r, I2C_CR1_STOP);
  m->rx[0] = (uint8_t)(STM32F4_RD(r->DR) & 0xFFu);
  m->rx[1] = (uint8_t)(STM32F4_RD(r->DR) & 0xFFu);
  return finish(m);
}

/* Before a START: the previous STOP has gone out (CR1.STOP cleared by the hardware)
 * and no one holds the bus (SR2.BUSY); a bus that never frees ends in the timeout. */
static void on_wait_free(stm32f4_i2c_master_t *m)
{
  stm32f4_i2c_t *r = m->cfg.regs;
  if ((STM32F4_RD(r->CR1) & I2C_CR1_STOP) != 0u) return;
  if ((STM32F4_RD(r->SR2) & I2C_SR2_BUSY) != 0u) return;
  request(r, I2C_CR1_START);
  m->state = ST_START;
}

stm32f4_i2c_status_t stm32f4_i2c_poll(stm32f4_i2c_master_t *m, uint32_t now_cycles)
{
  if (m == 0 || m->state == ST_IDLE) return STM32F4_I2C_IDLE;
  const uint32_t sr1 = STM32F4_RD(m->cfg.regs->SR1);
  /* AF: NACK (§27.6.6; a master must send STOP or restart, the reset does both); BERR,
   * ARLO: the bus is not ours; OVR cannot happen to a master that stretches the clock,
   * so it means the peripheral is confused. */
  if ((sr1 & I2C_SR1_AF) != 0u) return fail(m, STM32F4_I2C_ERR_NACK);
  if ((sr1 & I2C_SR1_ERRORS) != 0u) return fail(m, STM32F4_I2C_ERR_BUS);
  /* Unsigned difference: exact across the counter's wrap. */
  if (now_cycles - m->t_begin > m->cfg.timeout_cycles) {
    return fail(m, STM32F4_I2C_ERR_TIMEOUT);
  }
  switch (m->state) {
  case ST_WAIT_FREE: on_wait_free(m); break;
  case ST_START:
    if ((sr1 & I2C_SR1_SB) != 0u) on_start(m);
    break;
  case ST_ADDR:
    if ((sr1 & I2C_SR1_ADDR) != 0u) on_addr(m);
    break;
  case ST_TX: return on_tx(m, sr1);
  case ST_RX: return on_rx(m, sr1);
  default: return fail(m, STM32F4_I2C_ERR_BUS);
  }
  return STM32F4_I2C_BUSY;
}

const uint8_t *stm32f4_i2c_rx(const stm32f4_i2c_master_t *m) { return m->rx; }
