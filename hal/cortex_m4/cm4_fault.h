/* Fault capture: HardFault, MemManage, BusFault, UsageFault and any unexpected
 * interrupt store the stacked exception frame and the fault status registers into a
 * record in the .noinit RAM section (not touched by the start-up code, so it survives
 * the reset), then request a system reset. The bring-up tool and the product read the
 * record after the reset.
 *
 * Validity: magic and check = magic ^ count ^ pc ^ cfsr. Power-up RAM noise or a record
 * torn by a reset during its own write fails the check and reads as "no record". */
#ifndef CM4_FAULT_H
#define CM4_FAULT_H

#include <stdint.h>

#define CM4_FAULT_MAGIC 0xFA017EC0u

typedef struct {
  uint32_t magic;
  uint32_t count;      /* faults recorded since the record was last cleared */
  uint32_t exc_number; /* IPSR: 3 HardFault, 4 MemManage, 5 BusFault, 6 UsageFault, 16+n IRQ n */
  uint32_t r0, r1, r2, r3, r12, lr, pc, xpsr; /* stacked frame */
  uint32_t cfsr, hfsr, mmfar, bfar;           /* SCB fault status/address registers */
  uint32_t exc_return;                        /* LR at entry: which stack, FPU frame */
  uint32_t check;
} cm4_fault_record_t;

/* Copy the last record into out; 1 if there is a valid one, 0 if not. */
int cm4_fault_get(cm4_fault_record_t *out);
void cm4_fault_clear(void);

/* Fill the record from a stacked frame (r0, r1, r2, r3, r12, lr, pc, xpsr) and request a
 * system reset. On the target it does not return. */
void cm4_fault_capture(const uint32_t *frame, uint32_t exc_return, uint32_t exc_number);

/* Enable the configurable fault handlers and divide-by-zero trapping. */
void cm4_fault_enable(void);

#endif /* CM4_FAULT_H */
