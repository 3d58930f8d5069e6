#include "main_board_emu.h"

#include <string.h>

#include "comm/numparse.h"
#include "qemu_plant_setup.h"
#include "stm32f4_qemu.h"
#include "stm32f4_qemu_plant.h"

#define TRACE_LINES_PER_REPLY 16u /* 16 short lines: well inside the reply reserve */

static void emu_figures(cli_t *cli)
{
  stm32f4_qemu_tick_stats_t st;
  stm32f4_qemu_tick_stats(&st);
  cli_data_u32(cli, "stretch", st.stretch);
  cli_data_u32(cli, "period_ns", st.period_ns);
  cli_data_u32(cli, "ticks", st.ticks);
  cli_data_u32(cli, "tick_overruns", st.overruns);
  cli_data_u32(cli, "ticks_lost", st.lost);
  const float n = st.ticks > 0u ? (float)st.ticks : 1.0f;
  cli_data_u32(cli, "isr_ns_last", st.isr_ns_last);
  cli_data_u32(cli, "isr_ns_max", st.isr_ns_max);
  cli_data_f32(cli, "isr_ns_mean", (float)st.isr_ns_sum / n);
  cli_data_u32(cli, "plant_ns_last", st.plant_ns_last);
  cli_data_u32(cli, "plant_ns_max", st.plant_ns_max);
  cli_data_f32(cli, "plant_ns_mean", (float)st.plant_ns_sum / n);
  cli_data_f32(cli, "plant_rate_dps", (float)stm32f4_qemu_plant_rate_dps());
  cli_data_u32(cli, "trace_n", stm32f4_qemu_trace_count());
  cli_data_u32(cli, "trace_len", QEMU_TRACE_LEN);
  cli_data_u32(cli, "trace_every", QEMU_TRACE_EVERY);
  cli_ok(cli, "emu");
}

static void emu_rate(cli_t *cli, const char *arg)
{
  float v;
  if (numparse_f32(arg, strlen(arg), &v) != NUMPARSE_OK) {
    cli_err(cli, "VALUE", "rate: a number in deg/s");
    return;
  }
  const int rc = stm32f4_qemu_plant_set_rate((double)v);
  if (rc == -1) {
    cli_err(cli, "RANGE", "rate: |DPS| <= 10000");
    return;
  }
  if (rc != 0) {
    cli_err(cli, "BUSY", "the previous rate move has not been taken yet");
    return;
  }
  cli_put(cli, "rate ");
  cli_put_f32(cli, v);
  cli_emit_ok(cli);
}

/* `emu part default|fr`: another part in the emulator's socket (the drive off first: the
 * loops would otherwise see the old part's motion vanish as a fault). */
static void emu_part(cli_t *cli, app_t *a, const char *arg)
{
  const int part = strcmp(arg, "default") == 0 ? QEMU_PART_DEFAULT
                   : strcmp(arg, "fr") == 0    ? QEMU_PART_FR
                                               : -1;
  if (part < 0) {
    cli_err(cli, "VALUE", "part: default or fr");
    return;
  }
  if (a->gyro.sup.mode != GYRO_MODE_OFF) {
    cli_err(cli, "STATE", "part: drive off first");
    return;
  }
  if (stm32f4_qemu_plant_set_part(part) != 0) {
    cli_err(cli, "BUSY", "the previous part change has not been taken yet");
    return;
  }
  cli_put(cli, "part ");
  cli_put(cli, arg);
  cli_emit_ok(cli);
}

static void emu_stretch(cli_t *cli, const char *arg)
{
  uint32_t n;
  if (numparse_u32(arg, strlen(arg), &n) != NUMPARSE_OK || stm32f4_qemu_set_stretch(n) != 0) {
    cli_err(cli, "RANGE", "stretch N: 1..4993 sample periods per tick");
    return;
  }
  cli_put(cli, "stretch ");
  cli_put_u32(cli, n);
  cli_emit_ok(cli);
}

static void emu_trace(cli_t *cli, const char *arg)
{
  uint32_t from;
  if (numparse_u32(arg, strlen(arg), &from) != NUMPARSE_OK || from > QEMU_TRACE_LEN) {
    cli_err(cli, "RANGE", "trace FROM: 0..trace_len");
    return;
  }
  const uint32_t n = stm32f4_qemu_trace_count();
  for (uint32_t i = from; i < n && i < from + TRACE_LINES_PER_REPLY; ++i) {
    cli_put_u32(cli, i);
    cli_put(cli, " ");
    cli_put_f32(cli, stm32f4_qemu_trace_at(i));
    cli_emit_data(cli);
  }
  cli_put(cli, "trace ");
  cli_put_u32(cli, n);
  cli_emit_ok(cli);
}

static void cmd_emu(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  if (argc == 3u && strcmp(argv[1], "part") == 0) {
    emu_part(cli, ctx, argv[2]);
  } else if (argc == 1u) {
    emu_figures(cli);
  } else if (argc == 3u && strcmp(argv[1], "rate") == 0) {
    emu_rate(cli, argv[2]);
  } else if (argc == 3u && strcmp(argv[1], "stretch") == 0) {
    emu_stretch(cli, argv[2]);
  } else if (argc == 3u && strcmp(argv[1], "trace") == 0) {
    emu_trace(cli, argv[2]);
  } else {
    cli_err(cli, "ARGS",
            "usage: emu | emu rate DPS | emu part default|fr | emu stretch N | emu trace FROM");
  }
}

static cli_cmd_t s_emu_cmd; /* the CLI keeps rows by pointer */

int main_board_emu_init(app_t *a)
{
  const cli_cmd_t row = {"emu", "[rate DPS | part default|fr | stretch N | trace FROM]",
                         "emulator: tick and plant figures, input rate, part, rate trace",
                         cmd_emu, a};
  s_emu_cmd = row;
  stm32f4_qemu_plant_trace_from(&a->gyro.out.rate_dps);
  return cli_register(&a->cli, &s_emu_cmd);
}
