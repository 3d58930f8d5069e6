/* The command line fed arbitrary bytes. Byte 0 picks options: bit 0 the loop is safe
 * (save, non-live sets allowed), bit 1 received bytes are lost after every chunk
 * (cli_rx_lost), bit 2 it starts in console mode (the input may switch it with
 * "console on|off" too), bits 4-7 the chunk size the bytes arrive in, with an ISR tick
 * between chunks. Invariants: every reply line is well formed; any other output (echo,
 * prompt, erase) comes only in console mode, never as a NUL (the telemetry frame
 * delimiter) or a byte >= 0x80; the line held stays within CLI_LINE_MAX; the held
 * parameters always pass their checks and hold no -0, no staged edit is left behind,
 * every loss is counted; the input as a cli_putf format builds a well-formed line. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "comm/cli.h"
#include "comm/cli_builtin.h"
#include "fuzz_check.h"
#include "hal_flash_host.h"

typedef struct {
  params_t bank;
  param_store_t store;
  cli_t cli;
  bool safe;
  int derived[2];
} fx_t;

static fx_t g;

/* Console output: typed bytes echoed one by one, "\r\n", erase ("\b \b"), BEL, the
 * prompt, a recalled line. Never written with a CRLF at its end and 4 bytes or more,
 * which is how every reply line is written. */
static void check_console(const char *d, size_t n)
{
  FUZZ_CHECK(g.cli.console);
  FUZZ_CHECK(n >= 1u && n <= CLI_LINE_MAX + 16u);
  for (size_t i = 0; i < n; i++) {
    const char c = d[i];
    FUZZ_CHECK((c >= 0x20 && c <= 0x7E) || c == '\b' || c == '\a' || c == '\r' || c == '\n');
  }
}

static void check_line(void *ctx, const char *d, size_t n)
{
  (void)ctx;
  if (!(n >= 4u && d[n - 2] == '\r' && d[n - 1] == '\n')) {
    check_console(d, n);
    return;
  }
  FUZZ_CHECK(n <= CLI_OUT_MAX + 32u);
  for (size_t i = 0; i + 2 < n; i++) {
    FUZZ_CHECK(d[i] >= 0x20 && d[i] <= 0x7E);
  }
  const bool data = d[0] == '-' && d[1] == ' ';
  const bool ok = d[0] == 'o' && d[1] == 'k' && (d[2] == ' ' || d[2] == '\r');
  bool err = n > 6 && memcmp(d, "err ", 4) == 0;
  if (err) {
    size_t i = 4;
    while (i < n && d[i] >= 'A' && d[i] <= 'Z') {
      i++;
    }
    err = i > 4 && d[i] == ' ';
  }
  FUZZ_CHECK(data || ok || err);
}

static int derive(void *ctx, const param_values_t *v, void *d, const char **why)
{
  (void)ctx;
  if (v->drive_dc_bias_v >= v->drive_u_max_v) {
    *why = "drive.dc_bias_v must stay below drive.u_max_v";
    return 1;
  }
  *(int *)d = 1;
  return 0;
}

static bool loop_safe(void *ctx) { return ((fx_t *)ctx)->safe; }

/* The input, up to its first NUL, as a cli_putf format over one argument of each kind
 * (and fewer arguments than conversions, when it has many): the line it builds is well
 * formed (check_line) and within CLI_OUT_MAX whatever the format. */
static void putf_any(const uint8_t *data, size_t size)
{
  char fmt[2u * CLI_LINE_MAX + 1u];
  size_t n = 0u;
  while (n < size && n + 1u < sizeof fmt && data[n] != 0u) {
    fmt[n] = (char)data[n];
    n++;
  }
  fmt[n] = '\0';
  g.cli.replied = false;
  g.cli.out_len = 0u;
  cli_putf(&g.cli, fmt, "text", 4294967295u, -2147483647 - 1, -1.5e-38f, (const char *)NULL, 0);
  FUZZ_CHECK(g.cli.out_len + 2u <= CLI_OUT_MAX);
  cli_emit_data(&g.cli);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
  memset(&g, 0, sizeof g);
  const hal_flash_host_cfg_t fc = {2u, 2048u, NULL,
                                   0u, 0u,    0u}; /* an image of every parameter */
  FUZZ_CHECK(hal_flash_host_configure(&fc) == 0);
  const param_store_cfg_t sc = {0u, 1u};
  FUZZ_CHECK(param_store_init(&g.store, &sc) == PARAM_STORE_OK);
  const params_cfg_t pc = {derive, {&g.derived[0], &g.derived[1]}, loop_safe, &g};
  FUZZ_CHECK(params_init(&g.bank, &pc, NULL, NULL) == PARAM_OK);
  const cli_cfg_t cc = {&g.bank, &g.store,         check_line,
                        &g,      cli_builtin_cmds, cli_builtin_count()};
  FUZZ_CHECK(cli_init(&g.cli, &cc) == 0);
  if (size == 0) {
    return 0;
  }
  g.safe = (data[0] & 1u) != 0;
  if ((data[0] & 4u) != 0) {
    cli_set_console(&g.cli, true);
  }
  const bool lossy = (data[0] & 2u) != 0;
  uint32_t losses = 0u;
  const size_t chunk = 1u + (size_t)(data[0] >> 4) * 4u;
  for (size_t off = 1; off < size; off += chunk) {
    const size_t n = (size - off < chunk) ? size - off : chunk;
    cli_feed(&g.cli, data + off, n);
    if (lossy) {
      cli_rx_lost(&g.cli);
      losses++;
    }
    (void)params_isr_acquire(&g.bank);
    const param_values_t *cur = params_current(&g.bank);
    for (int i = 0; i < PARAM_COUNT; i++) {
      FUZZ_CHECK(param_check((param_idx_t)i, param_get(cur, (param_idx_t)i)) == PARAM_OK);
      FUZZ_CHECK(param_info((param_idx_t)i)->type != PARAM_T_F32 ||
                 param_get(cur, (param_idx_t)i).u != 0x80000000u);
    }
    FUZZ_CHECK(memcmp(params_staged(&g.bank), cur, sizeof *cur) == 0);
    FUZZ_CHECK(cur->sys_fs_hz == 50000u);
    FUZZ_CHECK(g.cli.len <= CLI_LINE_MAX && g.cli.last_len <= CLI_LINE_MAX);
  }
  FUZZ_CHECK(g.cli.truncated == 0u);
  FUZZ_CHECK(g.cli.rx_overflows == losses);
  putf_any(data + 1, size - 1u);
  return 0;
}
