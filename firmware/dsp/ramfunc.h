/* The code layout of the sample interrupt's path: GYRO_RAMFUNC marks a function of it
 * where it is defined, GYRO_UNLIKELY a branch of it rarely taken, GYRO_NOINLINE a rare
 * part of it kept out of its caller.
 *
 * On the target it puts the function into an input section of its own named
 * .ramfunc.<line>, which the linker script places in SRAM (no flash wait states, and it
 * runs on while a flash erase or program stalls flash fetches), whatever the function
 * is called; the target build's post-link check (linker/check_ramfunc.py) fails when a
 * function of the sample path lands outside SRAM. On the host it is nothing.
 *
 * Mark every function the sample interrupt may run (static helpers included: the
 * compiler may keep one out of line), in the LOCKED mode, SWEEP and a fault's clear.
 * The budget of the interrupt is in tools/bench/README.md. */
#ifndef RAMFUNC_H
#define RAMFUNC_H

#if defined(__arm__) && defined(__ARM_EABI__) && !defined(__linux__)
#define GYRO_RAMFUNC_STR2(x) #x
#define GYRO_RAMFUNC_STR(x) GYRO_RAMFUNC_STR2(x)
/* One input section per function (the line of its definition), so that
 * --gc-sections still drops what an image does not use. */
#define GYRO_RAMFUNC __attribute__((section(".ramfunc." GYRO_RAMFUNC_STR(__LINE__))))
#else
#define GYRO_RAMFUNC
#endif

/* A condition rarely true on the sample path: the compiler lays its branch out so that
 * the common path falls through (a taken branch refills the pipeline). Block layout
 * only, never what is computed. */
/* GYRO_NOINLINE keeps a rarely run part of it out of its caller, so that the caller's
 * common path saves no register for it. */
/* GYRO_COSTLY marks the branch whose work sets the interrupt's worst tick, though not
 * the common one (a feature that is off by default): laid out to fall through, since
 * the budget is the worst tick's. */
#if defined(__GNUC__)
#define GYRO_UNLIKELY(x) __builtin_expect((x) != 0, 0)
#define GYRO_COSTLY(x) __builtin_expect((x) != 0, 1)
#define GYRO_NOINLINE __attribute__((noinline))
#else
#define GYRO_UNLIKELY(x) ((x) != 0)
#define GYRO_COSTLY(x) ((x) != 0)
#define GYRO_NOINLINE
#endif

#endif /* RAMFUNC_H */
