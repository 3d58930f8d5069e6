#include "sim_bench.h"

#include <string.h>

#include "comm/numparse.h"
#include "plant/plant_const.h"

/* One number argument, or the default when absent; 0 on success. */
static int arg_f32(uint32_t argc, const char *const *argv, uint32_t i, float dflt, float *out)
{
  if (argc <= i) {
    *out = dflt;
    return 0;
  }
  return numparse_f32(argv[i], strlen(argv[i]), out) == NUMPARSE_OK ? 0 : -1;
}

static double t_now_s(const plant_t *p) { return (double)p->k * p->T; }

static void bench_figures(cli_t *cli, const sim_bench_t *b)
{
  cli_data_f32(cli, "t_s", (float)t_now_s(b->plant));
  cli_data_f32(cli, "rate_dps", (float)plant_input_now(b->plant, PLANT_INPUT_RATE));
  cli_data_f32(cli, "ambient_c",
               (float)(plant_input_now(b->plant, PLANT_INPUT_AMBIENT) - PLANT_K_AT_0_C));
  cli_data_f32(cli, "pace", (float)b->pace);
  cli_ok(cli, "emu");
}

/* `emu rate|ambient VALUE [EDGE_S]`: the move, or err with the reason. */
static void bench_move(cli_t *cli, const sim_bench_t *b, plant_input_t which, uint32_t argc,
                       const char *const *argv)
{
  const int rate = which == PLANT_INPUT_RATE;
  float v, edge_s;
  if (arg_f32(argc, argv, 2u, 0.0f, &v) != 0 ||
      arg_f32(argc, argv, 3u, (float)(rate ? SIM_BENCH_RATE_EDGE_S : SIM_BENCH_AMBIENT_EDGE_S),
              &edge_s) != 0) {
    cli_err(cli, "VALUE",
            rate ? "rate DPS [EDGE_S]: numbers, deg/s and s"
                 : "ambient DEGC [EDGE_S]: numbers, degC and s");
    return;
  }
  const double to = rate ? (double)v : (double)v + PLANT_K_AT_0_C;
  const double t_s = t_now_s(b->plant);
  if (plant_move_input(b->plant, which, to, (double)edge_s) != 0) {
    cli_err(cli, "RANGE",
            rate ? "rate: |DPS| <= 10000, 0 < EDGE_S <= 1e5"
                 : "ambient: -123.15..176.85 degC, 0 < EDGE_S <= 1e5");
    return;
  }
  cli_put(cli, rate ? "rate " : "ambient ");
  cli_put_f32(cli, v);
  cli_put(cli, " edge_s ");
  cli_put_f32(cli, edge_s);
  cli_put(cli, " t_s ");
  cli_put_f32(cli, (float)t_s);
  cli_emit_ok(cli);
}

/* `emu cold`: the part as after a long power-off (the flow then restarts the drive). */
static void bench_cold(cli_t *cli, const sim_bench_t *b)
{
  if (plant_cold_soak(b->plant) != 0) {
    cli_err(cli, "STATE", "cold: the thermal network refused the ambient");
    return;
  }
  cli_put(cli, "cold t_s ");
  cli_put_f32(cli, (float)t_now_s(b->plant));
  cli_emit_ok(cli);
}

static void cmd_emu(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  const sim_bench_t *b = ctx;
  if (argc == 1u) {
    bench_figures(cli, b);
  } else if (argc == 2u && strcmp(argv[1], "cold") == 0) {
    bench_cold(cli, b);
  } else if ((argc == 3u || argc == 4u) && strcmp(argv[1], "rate") == 0) {
    bench_move(cli, b, PLANT_INPUT_RATE, argc, argv);
  } else if ((argc == 3u || argc == 4u) && strcmp(argv[1], "ambient") == 0) {
    bench_move(cli, b, PLANT_INPUT_AMBIENT, argc, argv);
  } else {
    cli_err(cli, "ARGS",
            "usage: emu | emu rate DPS [EDGE_S] | emu ambient DEGC [EDGE_S] | emu cold");
  }
}

int sim_bench_register(sim_bench_t *b, cli_t *cli, plant_t *plant, double pace)
{
  b->plant = plant;
  b->pace = pace;
  const cli_cmd_t row = {"emu", "[rate DPS [EDGE_S] | ambient DEGC [EDGE_S] | cold]",
                         "simulated bench: the rate table, the chamber, a cold part", cmd_emu, b};
  b->row = row;
  return cli_register(cli, &b->row);
}
