/* The test bench of a paced gyro-sim session (--uart-pty): the `emu` command on the
 * firmware's command line turns the simulated rate table and sets the simulated chamber,
 * as the emulated board's `emu rate` turns its plant's table, so that a tool driving a
 * part over its UART (tools/calibrate --port, gyroctl) can move the inputs of a simulated
 * one the way an operator moves a real table and chamber. */
#ifndef SIM_BENCH_H
#define SIM_BENCH_H

#include "comm/cli.h"
#include "plant/plant.h"

/* Default edges of a move: a rate table's acceleration phase (the flow's scenarios' 0.1 s)
 * and a chamber's slew to a new plateau (the flow's 60 s). */
#define SIM_BENCH_RATE_EDGE_S 0.1
#define SIM_BENCH_AMBIENT_EDGE_S 60.0

typedef struct {
  plant_t *plant;
  double pace;   /* simulated seconds per wall second, 0: unpaced */
  cli_cmd_t row; /* the CLI keeps rows by pointer */
} sim_bench_t;

/* Registers `emu` on cli for the plant: `emu` (the bench's figures: t_s, rate_dps,
 * ambient_c, pace), `emu rate DPS [EDGE_S]`, `emu ambient DEGC [EDGE_S]` (a move from the
 * value now along a linear edge, then held; the reply gives the gyro time t_s at which it
 * starts), `emu cold` (every thermal node at the ambient, as after a long power-off:
 * plant_cold_soak). A bad value is refused with the reason and changes nothing. Returns
 * cli's. */
int sim_bench_register(sim_bench_t *b, cli_t *cli, plant_t *plant, double pace);

#endif /* SIM_BENCH_H */
