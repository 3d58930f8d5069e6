/* The board temperature sensor on the reference board (stm32f4_board_temp.c, a TMP117 on
 * I2C1) and the family's non-blocking I2C master under it (stm32f4_i2c.c), driven
 * through a fake I2C1 peripheral with a TMP117 on the bus. The fake plays the hardware
 * from the register file's access hook (stm32f4_regs.h: STM32F4_RD/WR): a START written
 * to CR1, the address or a data byte written to DR, SR2 read after ADDR, DR read, each
 * queues the peripheral's next event (SB, ADDR or AF, TXE, BTF, RXNE), which becomes
 * visible one step later, between two polls, as a bus transfer takes time. The fake
 * TMP117 answers register reads MSB first, clears Data_Ready when the Configuration or
 * the result register is read (SNOSD82D 7.6), and sends bytes as long as the master
 * ACKs them, so a wrong ACK/POS sequence shows as extra bytes (RM0090 §27.3.3). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "board.h"
#include "hal/hal_board_temp.h"
#include "stm32f4_board_temp.h"
#include "stm32f4_host_regs.h"
#include "stm32f4_i2c.h"

#define CYCLES_HZ 168000000u
#define PCLK1_HZ 42000000u
#define STEP_CYCLES 1680u /* one background pass every 10 us */
#define CYCLES_PER_MS (CYCLES_HZ / 1000u)
#define MAX_ACCESSES_PER_POLL 12u

typedef enum { EV_SB, EV_ADDR, EV_AF, EV_TXE, EV_TXDONE, EV_RXB, EV_STOP } fake_ev_t;

static struct {
  int stuck;     /* the START never goes out: no SB, ever */
  int nack_addr; /* nobody answers the address */
  uint16_t regs[16];
  uint8_t ptr;
  int reading;
  uint8_t out[2];
  uint32_t out_i;
  int send_more; /* the master ACKed the last byte: the sensor sends the next */
  uint8_t shift;
  int ack_at_addr;
  uint32_t cr1_last;
  fake_ev_t q[8];
  uint32_t qn;
  uint32_t accesses, swrst, reads[16], bytes_sent, protocol_errors, stops;
  uint8_t written[8]; /* data bytes written (after the address) since the last START */
  uint32_t written_n;
} f;

static void push(fake_ev_t ev)
{
  assert_true(f.qn < 8u);
  f.q[f.qn++] = ev;
}

static void on_cr1_write(uint32_t v)
{
  if ((v & I2C_CR1_SWRST) != 0u) {
    memset((void *)I2C1, 0, sizeof(*I2C1));
    I2C1->CR1 = v;
    ++f.swrst;
    f.qn = 0u;
    f.reading = 0;
    f.send_more = 0;
    f.cr1_last = v;
    return;
  }
  const uint32_t rising = v & ~f.cr1_last;
  f.cr1_last = v;
  if ((rising & I2C_CR1_START) != 0u && !f.stuck) push(EV_SB);
  if ((rising & I2C_CR1_STOP) != 0u) push(EV_STOP);
}

static void on_dr_write(uint32_t v)
{
  if ((I2C1->SR1 & I2C_SR1_SB) != 0u) { /* SR1 read, then DR written: SB cleared */
    I2C1->SR1 &= ~I2C_SR1_SB;
    f.reading = (int)(v & 1u);
    push(((v >> 1) != BOARD_TEMP_I2C_ADDR || f.nack_addr) ? EV_AF : EV_ADDR);
  } else if (!f.reading && (I2C1->SR2 & I2C_SR2_MSL) != 0u) {
    I2C1->SR1 &= ~(I2C_SR1_TXE | I2C_SR1_BTF);
    if (f.written_n == 0u) f.ptr = (uint8_t)(v & 0xFu); /* pointer (SNOSD82D 7.5.2) */
    if (f.written_n < 8u) f.written[f.written_n++] = (uint8_t)v;
    push(EV_TXDONE);
  } else {
    ++f.protocol_errors;
  }
}

static void on_sr2_read(void)
{
  if ((I2C1->SR1 & I2C_SR1_ADDR) == 0u) return;
  I2C1->SR1 &= ~I2C_SR1_ADDR;
  if (!f.reading) {
    push(EV_TXE);
    return;
  }
  const uint16_t v = f.regs[f.ptr];
  f.out[0] = (uint8_t)(v >> 8);
  f.out[1] = (uint8_t)(v & 0xFFu);
  f.out_i = 0u;
  f.bytes_sent = 0u;
  ++f.reads[f.ptr];
  if (f.ptr == TMP117_REG_CONFIG || f.ptr == TMP117_REG_TEMP) {
    f.regs[TMP117_REG_CONFIG] &= (uint16_t)~TMP117_CONFIG_DATA_READY;
  }
  f.ack_at_addr = (I2C1->CR1 & I2C_CR1_ACK) != 0u;
  push(EV_RXB);
}

static void on_dr_read(void)
{
  if ((I2C1->SR1 & I2C_SR1_BTF) != 0u) { /* the shift register's byte moves to DR */
    I2C1->DR = f.shift;
    I2C1->SR1 &= ~I2C_SR1_BTF;
  } else {
    I2C1->SR1 &= ~I2C_SR1_RXNE;
  }
  if (f.send_more) push(EV_RXB);
  f.send_more = 0;
}

static void access_hook(volatile uint32_t *reg, int is_write, uint32_t v)
{
  ++f.accesses;
  if (reg == &I2C1->CR1 && is_write) on_cr1_write(v);
  if (reg == &I2C1->DR && is_write) on_dr_write(v);
  if (reg == &I2C1->SR2 && !is_write) on_sr2_read();
  if (reg == &I2C1->DR && !is_write) on_dr_read();
}

/* A received byte: into DR, or with DR still full into the shift register (BTF, the
 * clock stretched until DR is read). ACK decided as the peripheral does: with POS the
 * first byte's by the ACK bit set before ADDR was cleared, otherwise the bit now. */
static void receive_byte(void)
{
  const uint32_t k = f.out_i++;
  const uint8_t byte = k < 2u ? f.out[k] : 0xFFu;
  f.bytes_sent = f.out_i;
  const int pos = (I2C1->CR1 & I2C_CR1_POS) != 0u;
  const int acked = (k == 0u && pos) ? f.ack_at_addr : (I2C1->CR1 & I2C_CR1_ACK) != 0u;
  if ((I2C1->SR1 & I2C_SR1_RXNE) != 0u) {
    f.shift = byte;
    I2C1->SR1 |= I2C_SR1_BTF;
    f.send_more = acked;
  } else {
    I2C1->DR = byte;
    I2C1->SR1 |= I2C_SR1_RXNE;
    f.send_more = 0;
    if (acked) push(EV_RXB);
  }
}

static void fake_tick(void)
{
  if (f.qn == 0u) return;
  const fake_ev_t ev = f.q[0];
  memmove(f.q, &f.q[1], (f.qn - 1u) * sizeof(f.q[0]));
  --f.qn;
  switch (ev) {
  case EV_SB:
    f.written_n = 0u;
    I2C1->CR1 &= ~I2C_CR1_START;
    f.cr1_last &= ~I2C_CR1_START;
    I2C1->SR1 = I2C_SR1_SB;
    I2C1->SR2 = I2C_SR2_MSL | I2C_SR2_BUSY;
    break;
  case EV_ADDR: I2C1->SR1 |= I2C_SR1_ADDR; break;
  case EV_AF: I2C1->SR1 |= I2C_SR1_AF; break;
  case EV_TXE: I2C1->SR1 |= I2C_SR1_TXE; break;
  case EV_TXDONE: I2C1->SR1 |= I2C_SR1_TXE | I2C_SR1_BTF; break;
  case EV_RXB: receive_byte(); break;
  case EV_STOP:
    I2C1->CR1 &= ~I2C_CR1_STOP;
    f.cr1_last &= ~I2C_CR1_STOP;
    I2C1->SR2 = 0u;
    ++f.stops;
    break;
  }
}

static uint32_t s_max_accesses;

/* One background pass: the bus moves one step, time passes, the driver polls. */
static hal_board_temp_event_t step(int16_t *code)
{
  fake_tick();
  DWT->CYCCNT += STEP_CYCLES;
  const uint32_t before = f.accesses;
  const hal_board_temp_event_t ev = hal_board_temp_poll(code);
  const uint32_t n = f.accesses - before;
  if (n > s_max_accesses) s_max_accesses = n;
  return ev;
}

/* Poll until an event other than NONE, at most max_steps passes; returns it (NONE if
 * none came) and the passes taken. */
static hal_board_temp_event_t run_until_event(int16_t *code, uint32_t max_steps, uint32_t *steps)
{
  for (uint32_t i = 1u; i <= max_steps; ++i) {
    const hal_board_temp_event_t ev = step(code);
    if (ev != HAL_BOARD_TEMP_NONE) {
      if (steps != 0) *steps = i;
      return ev;
    }
  }
  if (steps != 0) *steps = max_steps;
  return HAL_BOARD_TEMP_NONE;
}

static uint32_t steps_for_ms(uint32_t ms) { return ms * CYCLES_PER_MS / STEP_CYCLES; }

static int setup(void **state)
{
  (void)state;
  stm32f4_host_reset();
  memset(&f, 0, sizeof(f));
  f.regs[TMP117_REG_TEMP] = 0x8000u;   /* -256 degC until the first conversion (7.6) */
  f.regs[TMP117_REG_CONFIG] = 0x0220u; /* factory: continuous, 8 averages, 1 s (7.6) */
  f.regs[TMP117_REG_DEVICE_ID] = 0x0117u;
  stm32f4_host_map.access_hook = access_hook;
  s_max_accesses = 0u;
  DWT->CYCCNT = 0xFFF00000u; /* the cycle counter wraps during the tests */
  assert_int_equal(stm32f4_board_temp_start_at(PCLK1_HZ, CYCLES_HZ), 0);
  return 0;
}

static void conversion_done(uint16_t code)
{
  f.regs[TMP117_REG_TEMP] = code;
  f.regs[TMP117_REG_CONFIG] |= TMP117_CONFIG_DATA_READY;
}

/* RM0090 §27.6.8-9 at the board's PCLK1 (42 MHz): fast mode, DUTY 0, CCR 35 (exactly
 * 400 kHz), TRISE 300 ns x 42 MHz + 1 = 13; standard mode CCR 210, TRISE 43. */
static void test_timing_values(void **state)
{
  (void)state;
  stm32f4_i2c_timing_t t;
  assert_int_equal(stm32f4_i2c_timing(42000000u, 400000u, &t), 0);
  assert_int_equal(t.cr2_freq, 42);
  assert_int_equal(t.ccr, I2C_CCR_FS | 35u);
  assert_int_equal(t.trise, 13);
  assert_int_equal(stm32f4_i2c_timing(42000000u, 100000u, &t), 0);
  assert_int_equal(t.ccr, 210);
  assert_int_equal(t.trise, 43);
  /* On the 16 MHz HSI (clock tree failed): CCR rounded up, 381 kHz, never faster. */
  assert_int_equal(stm32f4_i2c_timing(16000000u, 400000u, &t), 0);
  assert_int_equal(t.ccr, I2C_CCR_FS | 14u);
  assert_int_equal(t.trise, 5);
  assert_int_equal(stm32f4_i2c_timing(3000000u, 400000u, &t), -1);  /* < 4 MHz in Fm */
  assert_int_equal(stm32f4_i2c_timing(50000000u, 400000u, &t), -1); /* FREQ <= 42 */
  assert_int_equal(stm32f4_i2c_timing(42000000u, 1000000u, &t), -1);
  assert_int_equal(stm32f4_i2c_timing(42000000u, 0u, &t), -1);
}

static void test_start_programs_bus_and_pins(void **state)
{
  (void)state;
  assert_true((RCC->APB1ENR & RCC_APB1ENR_I2C1EN) != 0u);
  assert_int_equal(I2C1->CR2, 42);
  assert_int_equal(I2C1->CCR, I2C_CCR_FS | 35u);
  assert_int_equal(I2C1->TRISE, 13);
  assert_int_equal(I2C1->CR1, I2C_CR1_PE);
  assert_int_equal(f.swrst, 1); /* a clean peripheral to start from */
  for (uint32_t pin = 8u; pin <= 9u; ++pin) {
    assert_int_equal((GPIOB->MODER >> (2u * pin)) & 3u, GPIO_MODE_AF);
    assert_int_equal((GPIOB->OTYPER >> pin) & 1u, 1);       /* open drain */
    assert_int_equal((GPIOB->PUPDR >> (2u * pin)) & 3u, 0); /* the board's pull-ups */
    assert_int_equal((GPIOB->AFR[1] >> (4u * (pin - 8u))) & 0xFu, 4);
  }
}

/* ID, then Data_Ready clear: NONE; set: the result, NEW with the code, once per
 * conversion; negative temperatures keep their sign. Each poll is a few accesses. */
static void test_read_cycle(void **state)
{
  (void)state;
  int16_t code = 0;
  assert_int_equal(run_until_event(&code, steps_for_ms(200u), NULL), HAL_BOARD_TEMP_NONE);
  assert_int_equal(f.reads[TMP117_REG_DEVICE_ID], 1);
  assert_true(f.reads[TMP117_REG_CONFIG] >= 4u);
  assert_int_equal(f.reads[TMP117_REG_TEMP], 0);
  assert_int_equal(f.bytes_sent, 2); /* the second byte NACKed: the sensor stopped */
  assert_int_equal(f.protocol_errors, 0);

  conversion_done(0x0C80u); /* 25 degC (SNOSD82D table 7-1) */
  assert_int_equal(run_until_event(&code, steps_for_ms(100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, 3200);
  assert_int_equal(f.reads[TMP117_REG_TEMP], 1);
  assert_int_equal(f.bytes_sent, 2);
  assert_int_equal(f.regs[TMP117_REG_CONFIG] & TMP117_CONFIG_DATA_READY, 0);
  /* No new conversion: nothing new, however long. */
  code = 1;
  assert_int_equal(run_until_event(&code, steps_for_ms(300u), NULL), HAL_BOARD_TEMP_NONE);
  assert_int_equal(code, 1);

  conversion_done(0xF380u); /* -25 degC */
  assert_int_equal(run_until_event(&code, steps_for_ms(100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, -3200);
  conversion_done(0xFFFFu); /* -0.0078125 degC */
  assert_int_equal(run_until_event(&code, steps_for_ms(100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, -1);
  conversion_done(0x8000u);
  assert_int_equal(run_until_event(&code, steps_for_ms(100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, -32768);
  assert_int_equal(stm32f4_board_temp_faults(), 0);
  assert_int_equal(f.protocol_errors, 0);
  assert_true(s_max_accesses <= MAX_ACCESSES_PER_POLL);
}

/* Data_Ready is checked no more often than every 50 ms: 20 checks in a second. */
static void test_rate_limited(void **state)
{
  (void)state;
  int16_t code;
  (void)run_until_event(&code, steps_for_ms(1000u), NULL);
  assert_true(f.reads[TMP117_REG_CONFIG] >= 20u);
  assert_true(f.reads[TMP117_REG_CONFIG] <= 21u);
  /* and a result does not shorten the interval: one check per 50 ms still */
  const uint32_t before = f.reads[TMP117_REG_CONFIG];
  for (uint32_t i = 0u; i < 10u; ++i) {
    conversion_done((uint16_t)(0x0C80u + i));
    assert_int_equal(run_until_event(&code, steps_for_ms(100u), NULL), HAL_BOARD_TEMP_NEW);
    assert_int_equal(code, 0x0C80 + (int)i);
  }
  const uint32_t checks = f.reads[TMP117_REG_CONFIG] - before;
  assert_true(checks <= 10u * 2u + 1u);
}

/* NACK on the address: FAULT with the peripheral reset and programmed again; the next
 * try (a sensor cycle later) identifies the sensor again and reads on. */
static void test_nack_faults_and_recovers(void **state)
{
  (void)state;
  f.nack_addr = 1;
  int16_t code = 0;
  uint32_t n = 0u;
  assert_int_equal(run_until_event(&code, 100u, &n), HAL_BOARD_TEMP_FAULT);
  assert_int_equal(f.swrst, 2);
  assert_int_equal(I2C1->CR1, I2C_CR1_PE);
  assert_int_equal(I2C1->CCR, I2C_CCR_FS | 35u);
  assert_int_equal(I2C1->TRISE, 13);
  assert_int_equal(I2C1->CR2, 42);
  assert_int_equal(I2C1->SR1, 0);
  assert_int_equal(stm32f4_board_temp_faults(), 1);
  /* Still absent: one try per second, each a FAULT. */
  assert_int_equal(run_until_event(&code, steps_for_ms(900u), NULL), HAL_BOARD_TEMP_NONE);
  assert_int_equal(run_until_event(&code, steps_for_ms(200u), NULL), HAL_BOARD_TEMP_FAULT);
  assert_int_equal(f.swrst, 3);
  f.nack_addr = 0;
  conversion_done(0x0C80u);
  const uint32_t ids = f.reads[TMP117_REG_DEVICE_ID];
  assert_int_equal(run_until_event(&code, steps_for_ms(1100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, 3200);
  assert_int_equal(f.reads[TMP117_REG_DEVICE_ID], ids + 1u);
  assert_int_equal(f.swrst, 3);
  assert_true(s_max_accesses <= MAX_ACCESSES_PER_POLL);
}

/* A stuck bus (the START never goes out): every poll returns at once, the transfer
 * times out after 10 ms, FAULT, the peripheral is reset; once the bus is back, reads. */
static void test_stuck_bus_times_out(void **state)
{
  (void)state;
  f.stuck = 1;
  int16_t code = 0;
  uint32_t n = 0u;
  assert_int_equal(run_until_event(&code, steps_for_ms(50u), &n), HAL_BOARD_TEMP_FAULT);
  const uint32_t timeout_steps = steps_for_ms(10u);
  assert_true(n >= timeout_steps && n <= timeout_steps + 3u);
  assert_int_equal(f.swrst, 2);
  assert_int_equal(I2C1->CR1, I2C_CR1_PE);
  assert_true(s_max_accesses <= MAX_ACCESSES_PER_POLL);
  f.stuck = 0;
  conversion_done(0x1900u); /* 50 degC */
  assert_int_equal(run_until_event(&code, steps_for_ms(1100u), NULL), HAL_BOARD_TEMP_NEW);
  assert_int_equal(code, 0x1900);
}

/* Another part at the address (a TMP116 says 0x1116): ABSENT, for good. */
static void test_wrong_device_id_is_absent(void **state)
{
  (void)state;
  f.regs[TMP117_REG_DEVICE_ID] = 0x1116u;
  int16_t code = 0;
  assert_int_equal(run_until_event(&code, 100u, NULL), HAL_BOARD_TEMP_ABSENT);
  conversion_done(0x0C80u);
  assert_int_equal(run_until_event(&code, steps_for_ms(200u), NULL), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(f.reads[TMP117_REG_CONFIG], 0);
}

/* A bus that cannot be set up: start fails, every poll says ABSENT and touches nothing.
 * hal_board_temp_start takes the board's clocks, which board_system_init has not set
 * here (all zero): the same failure through the HAL's own entry. */
static void test_start_failure_is_absent(void **state)
{
  (void)state;
  assert_int_equal(stm32f4_board_temp_start_at(3000000u, CYCLES_HZ), -1);
  int16_t code = 7;
  const uint32_t before = f.accesses;
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
  assert_int_equal(f.accesses, before);
  assert_int_equal(code, 7);
  assert_int_equal(hal_board_temp_start(), -1);
  assert_int_equal(hal_board_temp_poll(&code), HAL_BOARD_TEMP_ABSENT);
}

/* The master alone, on the same fake: a transfer run to its end, one step per pass. */
static stm32f4_i2c_status_t run_master(stm32f4_i2c_master_t *m, uint32_t max_steps)
{
  for (uint32_t i = 0u; i < max_steps; ++i) {
    fake_tick();
    DWT->CYCCNT += STEP_CYCLES;
    const stm32f4_i2c_status_t st = stm32f4_i2c_poll(m, DWT->CYCCNT);
    if (st != STM32F4_I2C_BUSY) return st;
  }
  return STM32F4_I2C_BUSY;
}

static void master_init(stm32f4_i2c_master_t *m)
{
  const stm32f4_i2c_config_t cfg = {.regs = I2C1,
                                    .rcc_apb1enr_bit = RCC_APB1ENR_I2C1EN,
                                    .pclk1_hz = PCLK1_HZ,
                                    .scl_hz = 400000u,
                                    .timeout_cycles = 10u * CYCLES_PER_MS};
  assert_int_equal(stm32f4_i2c_init(m, &cfg), 0);
}

/* A 1-byte read (RM0090 §27.3.3 Method 2, N = 1: ACK cleared before ADDR is, STOP right
 * after): the sensor sends one byte, NACKed; a write-only transfer ends with a STOP after
 * the last byte's BTF. */
static void test_master_one_byte_read_and_write(void **state)
{
  (void)state;
  stm32f4_i2c_master_t m;
  master_init(&m);
  const uint8_t ptr = TMP117_REG_DEVICE_ID;
  assert_int_equal(stm32f4_i2c_begin(&m, BOARD_TEMP_I2C_ADDR, &ptr, 1u, 1u, DWT->CYCCNT), 0);
  assert_int_equal(run_master(&m, 100u), STM32F4_I2C_DONE);
  assert_int_equal(stm32f4_i2c_rx(&m)[0], 0x01);
  assert_int_equal(f.bytes_sent, 1);
  assert_int_equal(f.send_more, 0);
  assert_int_equal(stm32f4_i2c_poll(&m, DWT->CYCCNT), STM32F4_I2C_IDLE);
  fake_tick(); /* the STOP goes out */
  assert_int_equal(f.stops, 1);
  assert_int_equal(I2C1->CR1 & (I2C_CR1_POS | I2C_CR1_ACK | I2C_CR1_STOP), 0);

  const uint8_t wr[3] = {0x02u, 0x60u, 0x00u}; /* THigh_Limit = 6000h */
  assert_int_equal(stm32f4_i2c_begin(&m, BOARD_TEMP_I2C_ADDR, wr, 3u, 0u, DWT->CYCCNT), 0);
  assert_int_equal(run_master(&m, 100u), STM32F4_I2C_DONE);
  assert_int_equal(f.written_n, 3);
  assert_memory_equal(f.written, wr, 3u);
  fake_tick();
  assert_int_equal(f.stops, 2);
  assert_int_equal(f.protocol_errors, 0);
  assert_int_equal(m.resets, 0);
}

static void test_master_begin_rejects(void **state)
{
  (void)state;
  stm32f4_i2c_master_t m;
  master_init(&m);
  const uint8_t tx[5] = {0};
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, tx, 0u, 0u, 0u), -1); /* nothing to do */
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, tx, 5u, 0u, 0u), -1); /* > TX_MAX */
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, tx, 1u, 3u, 0u), -1); /* > RX_MAX */
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, NULL, 1u, 0u, 0u), -1);
  assert_int_equal(stm32f4_i2c_begin(&m, 0x80u, tx, 1u, 0u, 0u), -1); /* not 7-bit */
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, tx, 1u, 2u, 0u), 0);
  assert_int_equal(stm32f4_i2c_begin(&m, 0x48u, tx, 1u, 2u, 0u), -1); /* one at a time */
  stm32f4_i2c_config_t bad = m.cfg;
  bad.pclk1_hz = 1000000u;
  assert_int_equal(stm32f4_i2c_init(&m, &bad), -1);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_timing_values),
      cmocka_unit_test_setup(test_start_programs_bus_and_pins, setup),
      cmocka_unit_test_setup(test_read_cycle, setup),
      cmocka_unit_test_setup(test_rate_limited, setup),
      cmocka_unit_test_setup(test_nack_faults_and_recovers, setup),
      cmocka_unit_test_setup(test_stuck_bus_times_out, setup),
      cmocka_unit_test_setup(test_wrong_device_id_is_absent, setup),
      cmocka_unit_test_setup(test_start_failure_is_absent, setup),
      cmocka_unit_test_setup(test_master_one_byte_read_and_write, setup),
      cmocka_unit_test_setup(test_master_begin_rejects, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
