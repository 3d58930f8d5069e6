/* Command line: reply grammar, line discipline, parameter commands end to end through
 * the bank and the A/B store on the flash stub. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <cmocka.h>

#include "comm/cli.h"
#include "comm/cli_builtin.h"
#include "comm/numparse.h"
#include "params/fw_version.h"
#include "hal_flash_host.h"

typedef struct {
  params_t bank;
  param_store_t store;
  cli_t cli;
  bool safe;
  char out[65536];
  size_t out_len;
  int derived[2];
} fx_t;

static fx_t g;

static void write_out(void *ctx, const char *d, size_t n)
{
  fx_t *fx = ctx;
  assert_true(fx->out_len + n < sizeof fx->out);
  memcpy(fx->out + fx->out_len, d, n);
  fx->out_len += n;
  fx->out[fx->out_len] = '\0';
}

static int derive(void *ctx, const param_values_t *v, void *d, const char **why)
{
  (void)ctx;
  /* an application-level cross-check: DC bias plus headroom must stay below u_max */
  if (v->drive_mode == 1u && v->drive_dc_bias_v >= v->drive_u_max_v) {
    *why = "drive.dc_bias_v must stay below drive.u_max_v";
    return 1;
  }
  *(int *)d = 1;
  return 0;
}

static bool loop_safe(void *ctx) { return ((fx_t *)ctx)->safe; }

static int setup(void **state)
{
  (void)state;
  memset(&g, 0, sizeof g);
  const hal_flash_host_cfg_t fc = {2u, 16384u, NULL, 0u, 0u, 0u};
  if (hal_flash_host_configure(&fc) != 0) {
    return -1;
  }
  const param_store_cfg_t sc = {0u, 1u};
  if (param_store_init(&g.store, &sc) != PARAM_STORE_OK) {
    return -1;
  }
  const params_cfg_t pc = {derive, {&g.derived[0], &g.derived[1]}, loop_safe, &g};
  if (params_init(&g.bank, &pc, NULL, NULL) != PARAM_OK) {
    return -1;
  }
  const cli_cfg_t cc = {&g.bank, &g.store,         write_out,
                        &g,      cli_builtin_cmds, cli_builtin_count()};
  return cli_init(&g.cli, &cc);
}

/* Every reply line is "- text", "ok[ text]" or "err CODE text"; the reply to each
 * non-blank command line ends with exactly one final line. Returns the final lines. */
static int check_grammar(const char *out)
{
  int finals = 0;
  const char *p = out;
  while (*p) {
    const char *eol = strstr(p, "\r\n");
    assert_non_null(eol);
    for (const char *q = p; q < eol; q++) {
      assert_true(*q >= 0x20 && *q <= 0x7E);
    }
    const size_t n = (size_t)(eol - p);
    if (n >= 2 && p[0] == '-' && p[1] == ' ') {
      /* data line */
    } else if (n >= 2 && p[0] == 'o' && p[1] == 'k' && (n == 2 || p[2] == ' ')) {
      finals++;
    } else if (n > 4 && strncmp(p, "err ", 4) == 0) {
      const char *c = p + 4;
      while (c < eol && *c >= 'A' && *c <= 'Z') {
        c++;
      }
      assert_true(c > p + 4 && c < eol && *c == ' ');
      finals++;
    } else {
      fail_msg("bad reply line: %.*s", (int)n, p);
    }
    p = eol + 2;
  }
  return finals;
}

/* Send text, then let the sample ISR run one tick (it picks up any publish). */
static const char *run(const char *text)
{
  g.out_len = 0;
  g.out[0] = '\0';
  cli_feed(&g.cli, (const uint8_t *)text, strlen(text));
  (void)params_isr_acquire(&g.bank);
  check_grammar(g.out);
  return g.out;
}

static void expect(const char *cmd, const char *reply)
{
  const char *got = run(cmd);
  if (strcmp(got, reply) != 0) {
    fail_msg("'%s' -> '%s', want '%s'", cmd, got, reply);
  }
}

static const param_values_t *cur(void) { return params_current(&g.bank); }

static void test_get_set(void **state)
{
  (void)state;
  expect("get drive.freq_hz\n", "ok drive.freq_hz 1750 Hz\r\n");
  expect("set drive.freq_hz 1500.5\n", "ok drive.freq_hz 1500.5\r\n");
  assert_true(cur()->drive_freq_hz == 1500.5f);
  expect("get drive.freq_hz\n", "ok drive.freq_hz 1500.5 Hz\r\n");
  expect("set tlm.rate_hz 250\n", "ok tlm.rate_hz 250\r\n");
  assert_int_equal(cur()->tlm_rate_hz, 250u);
  expect("get sys.fs_hz\n", "ok sys.fs_hz 50000 Hz\r\n");
  expect("get demod.mu_drive\n", "ok demod.mu_drive 0.034 -\r\n");
  expect("get nope\n", "err NAME unknown parameter 'nope'; try list\r\n");
  expect("get\n", "err ARGS usage: get NAME\r\n");
}

static void test_bad_values_change_nothing(void **state)
{
  (void)state;
  const param_values_t before = *cur();
  expect("set drive.freq_hz abc\n",
         "err VALUE drive.freq_hz: 'abc' is not a number; allowed [500,5000] Hz\r\n");
  expect("set drive.freq_hz 1e999\n",
         "err RANGE drive.freq_hz: '1e999' is out of range; allowed [500,5000] Hz\r\n");
  expect("set drive.freq_hz 6000\n",
         "err RANGE drive.freq_hz: '6000' is out of range; allowed [500,5000] Hz\r\n");
  expect("set drive.freq_hz nan\n",
         "err VALUE drive.freq_hz: 'nan' is not a number; allowed [500,5000] Hz\r\n");
  expect("set drive.freq_hz 1500x\n",
         "err VALUE drive.freq_hz: '1500x' is not a number; allowed [500,5000] Hz\r\n");
  expect("set tlm.rate_hz 2.5\n",
         "err VALUE tlm.rate_hz: '2.5' is not an unsigned integer; allowed [1,5000] Hz\r\n");
  expect("set tlm.rate_hz -1\n",
         "err VALUE tlm.rate_hz: '-1' is not an unsigned integer; allowed [1,5000] Hz\r\n");
  expect("set rate.lpf_order 5\n",
         "err RANGE rate.lpf_order: '5' is not a choice; allowed {2,4,6,8}\r\n");
  expect("set demod.mu_sense 0\n",
         "err RANGE demod.mu_sense: '0' is out of range; allowed [0.0001,0.49]\r\n");
  expect("set sys.fs_hz 40000\n", "err RO sys.fs_hz is read-only\r\n");
  expect("set drive.freq_hz\n", "err ARGS usage: set NAME VALUE [NAME VALUE ...]\r\n");
  expect("set drive.freq_hz 1 2\n", "err ARGS usage: set NAME VALUE [NAME VALUE ...]\r\n");
  /* all or nothing: the good first pair is not applied either */
  expect("set drive.amp_kp 2 drive.amp_ki -1\n",
         "err RANGE drive.amp_ki: '-1' is out of range; allowed [0,10000000] V^2/V/s\r\n");
  expect("set drive.amp_kp 2 bogus 1\n", "err NAME unknown parameter 'bogus'; try list\r\n");
  assert_memory_equal(cur(), &before, sizeof before);
  assert_memory_equal(params_staged(&g.bank), &before, sizeof before);
  expect("set drive.amp_kp 2 drive.amp_ki 40\n", "ok drive.amp_kp 2 drive.amp_ki 40\r\n");
  assert_true(cur()->drive_amp_kp == 2.0f && cur()->drive_amp_ki == 40.0f);
}

static void test_loop_running_refusals(void **state)
{
  (void)state;
  g.safe = false;
  expect("set drive.mode 1\n",
         "err BUSY drive.mode cannot change while the drive runs: stop the drive first\r\n");
  expect("save\n", "err BUSY drive running: stop the drive first\r\n");
  hal_flash_host_stats_t st;
  hal_flash_host_stats(&st);
  assert_int_equal(st.erases, 0u);
  expect("set drive.freq_hz 1490\n", "ok drive.freq_hz 1490\r\n"); /* live: allowed */
  g.safe = true;
  expect("set drive.mode 1\n", "ok drive.mode 1\r\n");
  /* the application's derive() can refuse a combination */
  expect(
      "set drive.dc_bias_v 13 drive.u_max_v 12\n",
      "err REJECTED drive.dc_bias_v 13, drive.u_max_v 12: drive.dc_bias_v must stay below drive.u_max_v\r\n");
  assert_true(cur()->drive_u_max_v == 12.75f);
}

static void test_pending_when_isr_has_not_ticked(void **state)
{
  (void)state;
  /* two sets in one burst: the ISR has not run in between */
  const char *out = run("set drive.freq_hz 1491\nset drive.freq_hz 1492\n");
  assert_string_equal(
      out,
      "ok drive.freq_hz 1491\r\nerr PENDING previous change not yet taken by the sample loop, retry\r\n");
  assert_true(cur()->drive_freq_hz == 1491.0f);
  expect("set drive.freq_hz 1492\n", "ok drive.freq_hz 1492\r\n");
}

static void test_save_load_defaults_diff(void **state)
{
  (void)state;
  g.safe = true;
  expect("diff\n", "ok 0 differ\r\n");
  expect("load\n",
         "err NOSTORE no valid parameter image (slot A empty, slot B empty); nothing changed\r\n");
  expect("set drive.freq_hz 1500 rate.bias_c1_dps_per_deg 34.59\n",
         "ok drive.freq_hz 1500 rate.bias_c1_dps_per_deg 34.59\r\n");
  expect(
      "diff\n",
      "- drive.freq_hz 1500 default 1750\r\n- rate.bias_c1_dps_per_deg 34.59 default 0\r\nok 2 differ\r\n");
  expect("save\n", "ok saved slot A seq 1\r\n");
  expect("save\n", "ok unchanged slot A seq 1\r\n");
  expect("defaults\n", "ok defaults applied (not saved)\r\n");
  expect("diff\n", "ok 0 differ\r\n");
  expect("load\n", "ok loaded slot A seq 1 dropped 0 rejected 0 defaulted 0\r\n");
  assert_true(cur()->drive_freq_hz == 1500.0f);
  expect("set drive.freq_hz 1501\n", "ok drive.freq_hz 1501\r\n");
  expect("save\n", "ok saved slot B seq 2\r\n");
  /* a stored non-live value cannot be loaded into a running loop */
  expect("set drive.mode 1\n", "ok drive.mode 1\r\n");
  expect("save\n", "ok saved slot A seq 3\r\n");
  expect("set drive.mode 0\n", "ok drive.mode 0\r\n");
  g.safe = false;
  expect("load\n",
         "err BUSY drive.mode cannot change while the drive runs: stop the drive first\r\n");
  assert_int_equal(cur()->drive_mode, 0u);
  g.safe = true;
  expect("set drive.mode 1\n", "ok drive.mode 1\r\n");
  g.safe = false;
  expect("defaults\n",
         "err BUSY drive.mode cannot change while the drive runs: stop the drive first\r\n");
}

static void test_line_discipline(void **state)
{
  (void)state;
  /* CR, LF, CRLF and blank lines; several commands in one burst */
  const char *out = run("get tlm.rate_hz\rget tlm.rate_hz\r\n\r\n   \t \nget tlm.rate_hz\n");
  assert_string_equal(
      out, "ok tlm.rate_hz 100 Hz\r\nok tlm.rate_hz 100 Hz\r\nok tlm.rate_hz 100 Hz\r\n");
  /* byte by byte, with tabs and extra spaces */
  g.out_len = 0;
  const char *cmd = "\t get   tlm.rate_hz \r\n";
  for (size_t i = 0; i < strlen(cmd); i++) {
    cli_feed(&g.cli, (const uint8_t *)&cmd[i], 1u);
  }
  assert_string_equal(g.out, "ok tlm.rate_hz 100 Hz\r\n");
  /* exactly CLI_LINE_MAX bytes is accepted, one more is discarded whole */
  char line[300];
  memset(line, ' ', sizeof line);
  memcpy(line, "get tlm.rate_hz", 15);
  line[CLI_LINE_MAX] = '\n';
  line[CLI_LINE_MAX + 1] = '\0';
  expect(line, "ok tlm.rate_hz 100 Hz\r\n");
  memcpy(line, "set tlm.rate_hz 7", 17);
  line[CLI_LINE_MAX] = ' ';
  line[CLI_LINE_MAX + 1] = '\n';
  line[CLI_LINE_MAX + 2] = '\0';
  expect(line, "err TOOLONG line longer than 120 bytes discarded\r\n");
  assert_int_equal(cur()->tlm_rate_hz, 100u);
  /* NUL and binary bytes reject the line; the next line works */
  const uint8_t nul[] = {'s', 'e', 't', ' ', 't', 'l', 'm', '.', 'r', 'a',
                         't', 'e', '_', 'h', 'z', ' ', '7', 0,   '\n'};
  g.out_len = 0;
  cli_feed(&g.cli, nul, sizeof nul);
  assert_string_equal(g.out, "err BADCHAR line with a non-printable byte discarded\r\n");
  const uint8_t bin[] = {0xFF, 0x80, 0x1B, '[', 'A', 0x7F, '\n', 'g', 'e', 't', ' ',
                         's',  'y',  's',  '.', 'f', 's',  '_',  'h', 'z', '\n'};
  g.out_len = 0;
  cli_feed(&g.cli, bin, sizeof bin);
  assert_string_equal(
      g.out, "err BADCHAR line with a non-printable byte discarded\r\nok sys.fs_hz 50000 Hz\r\n");
  assert_int_equal(cur()->tlm_rate_hz, 100u);
  expect("frobnicate 1 2\n", "err UNKNOWN no command 'frobnicate'; try help\r\n");
  expect("a b c d e f g h i j k l m n o p q\n", "err ARGS too many words on the line\r\n");
}

static void test_list(void **state)
{
  (void)state;
  const char *out = run("list\n");
  int lines = 0;
  for (const char *p = out; *p != '\0'; p = strstr(p, "\r\n") + 2) {
    if (p[0] == '-') {
      char name[64], value[32], unit[32], range[64];
      assert_int_equal(sscanf(p, "- %63s %31s %31s %63s", name, value, unit, range), 4);
      const param_idx_t i = param_lookup(name, strlen(name));
      assert_int_not_equal(i, PARAM_COUNT);
      assert_string_equal(unit, param_info(i)->unit);
      /* the printed value reads back to exactly the held value */
      param_value_t v;
      if (param_info(i)->type == PARAM_T_F32) {
        assert_int_equal(numparse_f32(value, strlen(value), &v.f), NUMPARSE_OK);
      } else {
        assert_int_equal(numparse_u32(value, strlen(value), &v.u), NUMPARSE_OK);
      }
      assert_int_equal(v.u, param_get(cur(), i).u);
      assert_non_null(strstr(p, param_info(i)->help));
      lines++;
    }
  }
  assert_int_equal(lines, PARAM_COUNT);
  char tail[64];
  snprintf(tail, sizeof tail, "ok %d parameters\r\n", PARAM_COUNT);
  assert_string_equal(out + strlen(out) - strlen(tail), tail);
  assert_int_equal(g.cli.truncated, 0u);
  assert_non_null(
      strstr(out, "- drive.freq_hz 1750 Hz [500,5000] def=1750 flags=PL drive frequency"));
  assert_non_null(strstr(out, "- drive.mode 0 - {0,1} def=0 flags=P "));
  assert_non_null(strstr(out, "- sys.fs_hz 50000 Hz [50000,50000] def=50000 flags=R "));
  out = run("list rate.bias\n");
  assert_int_equal(check_grammar(out), 1);
  assert_non_null(strstr(out, "ok 5 parameters\r\n")); /* c0..c3 and the gradient term */
  expect("list zzz\n", "ok 0 parameters\r\n");
  expect("list a b\n", "err ARGS usage: list [PREFIX]\r\n");
}

static void app_status(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  cli_put(cli, "mode IDLE args ");
  cli_put_u32(cli, argc);
  cli_emit_ok(cli);
}

static void app_silent(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)cli;
  (void)ctx;
  (void)argc;
  (void)argv;
}

static void app_chatty(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argc;
  (void)argv;
  cli_put(cli, "line\r\nwith a break");
  cli_emit_data(cli);
  cli_ok(cli, "first");
  cli_err(cli, "LATE", "second final line is dropped");
}

static void test_app_commands_and_help(void **state)
{
  (void)state;
  static const cli_cmd_t status = {"status", "", "loop mode and faults", app_status, NULL};
  static const cli_cmd_t stream = {"stream", "FIELD... @RATE_HZ", "start telemetry", app_status,
                                   NULL};
  static const cli_cmd_t silent = {"silent", "", "forgets to reply", app_silent, NULL};
  static const cli_cmd_t chatty = {"chatty", "", "replies twice", app_chatty, NULL};
  static const cli_cmd_t dup = {"status", "", "again", app_status, NULL};
  static const cli_cmd_t builtin = {"set", "", "shadow", app_status, NULL};
  static const cli_cmd_t spaced = {"two words", "", "bad", app_status, NULL};
  static const cli_cmd_t nofn = {"nofn", "", "bad", NULL, NULL};
  assert_int_equal(cli_register(&g.cli, &status), 0);
  assert_int_equal(cli_register(&g.cli, &stream), 0);
  assert_int_equal(cli_register(&g.cli, &silent), 0);
  assert_int_equal(cli_register(&g.cli, &chatty), 0);
  assert_int_equal(cli_register(&g.cli, &dup), -1);
  assert_int_equal(cli_register(&g.cli, &builtin), -1);
  assert_int_equal(cli_register(&g.cli, &spaced), -1);
  assert_int_equal(cli_register(&g.cli, &nofn), -1);
  expect("status\n", "ok mode IDLE args 1\r\n");
  expect("stream rate_dps quad_dps @100\n", "ok mode IDLE args 4\r\n");
  expect("silent\n", "err INTERNAL handler gave no reply\r\n");
  expect("chatty\n", "- line??with a break\r\nok first\r\n");
  const char *out = run("help\n");
  assert_int_equal(check_grammar(out), 1);
  const char *names[] = {"help",     "list", "get",     "set",    "save",  "load",
                         "defaults", "diff", "version", "status", "stream"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    char needle[32];
    snprintf(needle, sizeof needle, "- %s ", names[i]);
    assert_non_null(strstr(out, needle));
  }
  assert_non_null(strstr(out, "- stream FIELD... @RATE_HZ : start telemetry\r\n"));
  assert_non_null(strstr(out, "ok 14 commands\r\n"));
  static cli_cmd_t more[8];
  static char more_names[8][8];
  int added = 0;
  for (int k = 0; k < 8; k++) {
    snprintf(more_names[k], sizeof more_names[k], "x%d", k);
    more[k] = (cli_cmd_t){more_names[k], "", "filler", app_status, NULL};
    added += (cli_register(&g.cli, &more[k]) == 0);
  }
  assert_int_equal(added, CLI_MAX_APP_CMDS - 4);
}

/* Console output has echo and prompts between the reply lines: compared whole. */
static void cexpect(const char *typed, const char *screen)
{
  g.out_len = 0;
  g.out[0] = '\0';
  cli_feed(&g.cli, (const uint8_t *)typed, strlen(typed));
  if (strcmp(g.out, screen) != 0) {
    fail_msg("'%s' -> '%s', want '%s'", typed, g.out, screen);
  }
}

/* Console mode: prompt, echo, editing; machine mode stays the default and unchanged. */
static void test_console_prompt_and_echo(void **state)
{
  (void)state;
  cexpect("console\n", "ok console off\r\n");
  cexpect("console on\r\n", "ok console on\r\ngyro> ");
  /* typed byte by byte as at a terminal, Enter sends CR */
  g.out_len = 0;
  const char *typed = "get tlm.rate_hz\r";
  for (size_t i = 0; i < strlen(typed); i++) {
    cli_feed(&g.cli, (const uint8_t *)&typed[i], 1u);
  }
  assert_string_equal(g.out, "get tlm.rate_hz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  /* CR LF is one Enter; a blank line gives a new prompt only; a tab is a space */
  cexpect("get\ttlm.rate_hz\r\n", "get tlm.rate_hz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  cexpect("\r", "\r\ngyro> ");
  cexpect("  \n", "  \r\ngyro> ");
  cexpect("nope\n", "nope\r\nerr UNKNOWN no command 'nope'; try help\r\ngyro> ");
  cexpect("console bad\r", "console bad\r\nerr ARGS usage: console [on|off]\r\ngyro> ");
  /* back to machine mode: no prompt, no echo */
  cexpect("console off\r", "console off\r\nok console off\r\n");
  cexpect("get tlm.rate_hz\r\n", "ok tlm.rate_hz 100 Hz\r\n");
  const uint8_t bs[] = {'x', 0x7F, '\n'};
  g.out_len = 0;
  cli_feed(&g.cli, bs, sizeof bs);
  assert_string_equal(g.out, "err BADCHAR line with a non-printable byte discarded\r\n");
}

static void test_console_editing(void **state)
{
  (void)state;
  cexpect("console on\n", "ok console on\r\ngyro> ");
  /* Up before any line was run: nothing to bring back, nothing written */
  cexpect("\x1b[A", "");
  /* Backspace (DEL) and Ctrl-H */
  cexpect("get tlm.rate_hx\x7fz\r", "get tlm.rate_hx\b \bz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  cexpect("get tlm.ratx\be_hz\r", "get tlm.ratx\b \be_hz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  /* backspace on an empty line does nothing */
  cexpect("\x7f\b", "");
  /* Ctrl-U erases the line, Ctrl-C drops it with a new prompt: neither is run */
  cexpect("set tlm.rate_hz 7\x15", "set tlm.rate_hz 7\b \b\b \b\b \b\b \b\b \b\b \b\b \b\b \b"
                                   "\b \b\b \b\b \b\b \b\b \b\b \b\b \b\b \b\b \b");
  cexpect("\r", "\r\ngyro> ");
  cexpect("set tlm.rate_hz 7\x03", "set tlm.rate_hz 7^C\r\ngyro> ");
  cexpect("\r", "\r\ngyro> ");
  assert_int_equal(cur()->tlm_rate_hz, 100u);
  /* arrows and other keys: consumed, no error, the line goes on */
  cexpect("get \x1b[C\x1b[D\x1bOB\x1b[1;5D\x1b[3~\x1bxtlm.rate_hz\r",
          "get tlm.rate_hz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  /* other control bytes and bytes >= 0x80 are ignored */
  const uint8_t odd[] = {'g', 0x00, 0x01, 0xC3, 0xA9, 0xFF, 'e', 't', ' ', 's',
                         'y', 's',  '.',  'f',  's',  '_',  'h', 'z', '\r'};
  g.out_len = 0;
  cli_feed(&g.cli, odd, sizeof odd);
  assert_string_equal(g.out, "get sys.fs_hz\r\nok sys.fs_hz 50000 Hz\r\ngyro> ");
  /* Up brings back the last line run, replacing what was typed */
  cexpect("xy\x1b[A", "xy\b \b\b \bget sys.fs_hz");
  cexpect("\r", "\r\nok sys.fs_hz 50000 Hz\r\ngyro> ");
  cexpect("\x1bOA\r", "get sys.fs_hz\r\nok sys.fs_hz 50000 Hz\r\ngyro> ");
  /* a full line refuses more with BEL instead of discarding it */
  char line[CLI_LINE_MAX + 8u];
  memset(line, ' ', sizeof line);
  memcpy(line, "get tlm.rate_hz", 15);
  line[CLI_LINE_MAX + 2u] = '\0';
  g.out_len = 0;
  cli_feed(&g.cli, (const uint8_t *)line, strlen(line));
  assert_int_equal(g.out_len, CLI_LINE_MAX + 2u);
  assert_string_equal(&g.out[CLI_LINE_MAX], "\a\a");
  cexpect("\r", "\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  /* lost input still discards the line */
  cexpect("get tlm", "get tlm");
  cli_rx_lost(&g.cli);
  cexpect(
      ".rate_hz\r",
      ".rate_hz\r\nerr OVERFLOW input lost (receive buffer full): line discarded, send it again\r\ngyro> ");
  /* an escape sequence cut by Enter does not eat the next line */
  cexpect("\x1b[\r", "\r\ngyro> ");
  cexpect("get tlm.rate_hz\r", "get tlm.rate_hz\r\nok tlm.rate_hz 100 Hz\r\ngyro> ");
  /* one byte per call, so the application can check for TX room before each echo */
  assert_int_equal(cli_feed_line(&g.cli, (const uint8_t *)"ab\r", 3u), 1u);
}

static void test_version(void **state)
{
  (void)state;
  char want[128];
  snprintf(want, sizeof want, "ok fw %s layout %u format 1 params %d\r\n", fw_version_string(),
           PARAM_LAYOUT_VERSION, PARAM_COUNT);
  expect("version\n", want);
}

/* cli_putf: the text of each conversion equals what the single-purpose appends give,
 * every mistake shows as '?', and the line stays bounded. */
static const char *putf_line(void)
{
  g.out_len = 0u;
  g.cli.replied = false;
  cli_emit_ok(&g.cli);
  return g.out;
}

static void test_putf(void **state)
{
  (void)state;
  const uint32_t u = 4294967295u;
  const int32_t d = -2147483647 - 1;
  const float f = 0.1f;
  const char *s = "rate";
  cli_putf(&g.cli, "%s %u %d %f %%x", s, u, d, f);
  assert_string_equal(putf_line(), "ok rate 4294967295 -2147483648 0.1 %x\r\n");
  cli_putf(&g.cli, "%u%u|%d|%f", (uint8_t)7, 0, 12, 1e-7f);
  assert_string_equal(putf_line(), "ok 70|12|1e-7\r\n");
  /* kind mismatches, out-of-range integers, an unknown conversion, a missing argument,
   * a NULL string, a '%' at the very end */
  const char *none = NULL;
  cli_putf(&g.cli, "%f %s %u %d %x %s%s %u %", 1u, 2.0f, -1, (int64_t)1 << 40, 5u, none, "z");
  assert_string_equal(putf_line(), "ok ? ? ? ? ? z ? ?\r\n");
  /* as the appends it replaces: the same bytes */
  cli_put(&g.cli, "stream ");
  cli_put_u32(&g.cli, 3u);
  cli_put(&g.cli, " ");
  cli_put_f32(&g.cli, 333.33334f);
  cli_put(&g.cli, " Hz");
  char want[64];
  const char *line = putf_line();
  assert_true(strlen(line) < sizeof want);
  memcpy(want, line, strlen(line) + 1u);
  cli_putf(&g.cli, "stream %u %f Hz", 3u, 333.33334f);
  assert_string_equal(putf_line(), want);
  /* bounded: a long argument is cut at CLI_OUT_MAX like any append, and counted */
  char big[2u * CLI_OUT_MAX];
  memset(big, 'a', sizeof big - 1u);
  big[sizeof big - 1u] = '\0';
  const uint32_t cut = g.cli.truncated;
  cli_putf(&g.cli, "%s%u", big, 1u);
  assert_int_equal(strlen(putf_line()), CLI_OUT_MAX - 2u + 3u + 2u);
  assert_true(g.cli.truncated > cut);
}

int main(void)
{
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_get_set, setup),
      cmocka_unit_test_setup(test_bad_values_change_nothing, setup),
      cmocka_unit_test_setup(test_loop_running_refusals, setup),
      cmocka_unit_test_setup(test_pending_when_isr_has_not_ticked, setup),
      cmocka_unit_test_setup(test_save_load_defaults_diff, setup),
      cmocka_unit_test_setup(test_line_discipline, setup),
      cmocka_unit_test_setup(test_list, setup),
      cmocka_unit_test_setup(test_app_commands_and_help, setup),
      cmocka_unit_test_setup(test_version, setup),
      cmocka_unit_test_setup(test_putf, setup),
      cmocka_unit_test_setup(test_console_prompt_and_echo, setup),
      cmocka_unit_test_setup(test_console_editing, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
