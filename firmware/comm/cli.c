/* Line discipline, tokenising, dispatch and reply framing of the command line; the
 * built-in parameter commands (cli_builtin.c) come in through cli_cfg_t. Grammar in cli.h. */
#include "comm/cli.h"

#include <string.h>

#include "comm/numfmt.h"

static bool is_wsp(char c) { return c == ' ' || c == '\t'; }

int cli_init(cli_t *cli, const cli_cfg_t *cfg)
{
  memset(cli, 0, sizeof *cli);
  if (cfg == NULL || cfg->params == NULL || cfg->write == NULL ||
      (cfg->builtin == NULL && cfg->n_builtin != 0u)) {
    return -1;
  }
  cli->cfg = *cfg;
  return 0;
}

static const cli_cmd_t *find_cmd(const cli_t *cli, const char *name)
{
  for (uint32_t i = 0; i < cli_cmd_count(cli); i++) {
    const cli_cmd_t *c = cli_cmd_at(cli, i);
    if (strcmp(c->name, name) == 0) {
      return c;
    }
  }
  return NULL;
}

int cli_register(cli_t *cli, const cli_cmd_t *cmd)
{
  if (cmd == NULL || cmd->fn == NULL || cmd->name == NULL || cmd->name[0] == '\0' ||
      cli->n_app >= CLI_MAX_APP_CMDS) {
    return -1;
  }
  for (const char *p = cmd->name; *p != '\0'; p++) {
    if (*p <= ' ' || *p > '~') {
      return -1;
    }
  }
  if (find_cmd(cli, cmd->name) != NULL) {
    return -1;
  }
  cli->app[cli->n_app++] = cmd;
  return 0;
}

uint32_t cli_cmd_count(const cli_t *cli) { return cli->cfg.n_builtin + cli->n_app; }

const cli_cmd_t *cli_cmd_at(const cli_t *cli, uint32_t i)
{
  if (i < cli->cfg.n_builtin) {
    return &cli->cfg.builtin[i];
  }
  i -= cli->cfg.n_builtin;
  return (i < cli->n_app) ? cli->app[i] : NULL;
}

/* ---- reply framing ---- */

void cli_put_n(cli_t *cli, const char *s, size_t n)
{
  for (size_t i = 0; i < n && s[i] != '\0'; i++) {
    if (cli->out_len + 2u >= CLI_OUT_MAX) { /* keep room for CRLF */
      cli->truncated++;
      return;
    }
    const char c = s[i];
    cli->out[cli->out_len++] = (c >= ' ' && c <= '~') ? c : '?';
  }
}

void cli_put(cli_t *cli, const char *s)
{
  if (s != NULL) {
    cli_put_n(cli, s, strlen(s));
  }
}

void cli_put_f32(cli_t *cli, float x)
{
  char buf[NUMFMT_F32_MAX];
  const size_t n = numfmt_f32(buf, sizeof buf, x);
  cli_put_n(cli, buf, n);
}

void cli_put_u32(cli_t *cli, uint32_t x)
{
  char buf[NUMFMT_U32_MAX];
  const size_t n = numfmt_u32(buf, sizeof buf, x);
  cli_put_n(cli, buf, n);
}

static void put_int(cli_t *cli, char conv, const cli_arg_t *a)
{
  if (a->kind != (uint8_t)'i') {
    cli_put(cli, "?");
  } else if (conv == 'u' && a->i >= 0 && a->i <= (int64_t)UINT32_MAX) {
    cli_put_u32(cli, (uint32_t)a->i);
  } else if (conv == 'd' && a->i >= (int64_t)INT32_MIN && a->i <= (int64_t)INT32_MAX) {
    if (a->i < 0) {
      cli_put(cli, "-");
    }
    cli_put_u32(cli, (uint32_t)(a->i < 0 ? -a->i : a->i));
  } else {
    cli_put(cli, "?");
  }
}

void cli_putf_args(cli_t *cli, const char *fmt, const cli_arg_t *args, uint32_t n)
{
  uint32_t k = 0u;
  const char *text = fmt;
  const char *p = fmt;
  while (*p != '\0') {
    if (*p != '%') {
      p++;
      continue;
    }
    cli_put_n(cli, text, (size_t)(p - text));
    const char conv = p[1];
    p += (conv != '\0') ? 2 : 1;
    text = p;
    if (conv == '%') {
      cli_put(cli, "%");
      continue;
    }
    const cli_arg_t *a = (k < n) ? &args[k] : NULL;
    k++;
    if (a == NULL) {
      cli_put(cli, "?");
    } else if (conv == 's' && a->kind == (uint8_t)'s') {
      cli_put(cli, a->s);
    } else if (conv == 'f' && a->kind == (uint8_t)'f') {
      cli_put_f32(cli, a->f);
    } else if (conv == 'u' || conv == 'd') {
      put_int(cli, conv, a);
    } else {
      cli_put(cli, "?");
    }
  }
  cli_put_n(cli, text, (size_t)(p - text));
}

void cli_data_u32(cli_t *cli, const char *key, uint32_t v)
{
  cli_put(cli, key);
  cli_put(cli, " ");
  cli_put_u32(cli, v);
  cli_emit_data(cli);
}

void cli_data_f32(cli_t *cli, const char *key, float v)
{
  cli_put(cli, key);
  cli_put(cli, " ");
  cli_put_f32(cli, v);
  cli_emit_data(cli);
}

/* Send prefix + the built text + CRLF, then clear the builder. */
static void emit(cli_t *cli, const char *prefix, bool final)
{
  if (cli->replied) {
    cli->out_len = 0u; /* the command already ended: keep the grammar */
    return;
  }
  char line[CLI_OUT_MAX + 32u];
  size_t n = strlen(prefix);
  memcpy(line, prefix, n);
  memcpy(&line[n], cli->out, cli->out_len);
  n += cli->out_len;
  line[n++] = '\r';
  line[n++] = '\n';
  cli->out_len = 0u;
  cli->replied = final;
  cli->cfg.write(cli->cfg.write_ctx, line, n);
}

void cli_emit_data(cli_t *cli) { emit(cli, "- ", false); }

void cli_emit_ok(cli_t *cli) { emit(cli, (cli->out_len > 0u) ? "ok " : "ok", true); }

void cli_emit_err(cli_t *cli, const char *code)
{
  char prefix[24] = "err ";
  size_t n = 4u;
  for (const char *p = code; p != NULL && *p != '\0' && n + 2u < sizeof prefix; p++) {
    prefix[n++] = (*p >= 'A' && *p <= 'Z') ? *p : '?';
  }
  prefix[n++] = ' ';
  prefix[n] = '\0';
  emit(cli, prefix, true);
}

void cli_ok(cli_t *cli, const char *msg)
{
  cli->out_len = 0u;
  cli_put(cli, msg);
  cli_emit_ok(cli);
}

void cli_err(cli_t *cli, const char *code, const char *msg)
{
  cli->out_len = 0u;
  cli_put(cli, msg);
  cli_emit_err(cli, code);
}

/* ---- line discipline ---- */

static void execute(cli_t *cli)
{
  const char *argv[CLI_MAX_ARGS + 1u];
  uint32_t argc = 0u;
  char *p = cli->line;
  cli->line[cli->len] = '\0';
  while (*p != '\0') {
    while (is_wsp(*p)) {
      *p++ = '\0';
    }
    if (*p == '\0') {
      break;
    }
    if (argc == CLI_MAX_ARGS) {
      cli_err(cli, "ARGS", "too many words on the line");
      return;
    }
    argv[argc++] = p;
    while (*p != '\0' && !is_wsp(*p)) {
      p++;
    }
  }
  if (argc == 0u) {
    return; /* blank line: no reply */
  }
  argv[argc] = NULL;
  const cli_cmd_t *cmd = find_cmd(cli, argv[0]);
  if (cmd == NULL) {
    cli->out_len = 0u;
    cli_put(cli, "no command '");
    cli_put(cli, argv[0]);
    cli_put(cli, "'; try help");
    cli_emit_err(cli, "UNKNOWN");
    return;
  }
  cmd->fn(cli, cmd->ctx, argc, argv);
  if (!cli->replied) {
    cli_err(cli, "INTERNAL", "handler gave no reply");
  }
}

static void write_raw(cli_t *cli, const char *s, size_t n)
{
  cli->cfg.write(cli->cfg.write_ctx, s, n);
}

static void end_of_line(cli_t *cli)
{
  cli->replied = false;
  cli->out_len = 0u;
  if (cli->discard == (uint8_t)CLI_DISCARD_TOOLONG) {
    cli_put(cli, "line longer than ");
    cli_put_u32(cli, CLI_LINE_MAX);
    cli_put(cli, " bytes discarded");
    cli_emit_err(cli, "TOOLONG");
  } else if (cli->discard == (uint8_t)CLI_DISCARD_BADCHAR) {
    cli_err(cli, "BADCHAR", "line with a non-printable byte discarded");
  } else if (cli->discard == (uint8_t)CLI_DISCARD_OVERFLOW) {
    cli_err(cli, "OVERFLOW", "input lost (receive buffer full): line discarded, send it again");
  } else if (cli->len > 0u) {
    execute(cli);
  }
  cli->len = 0u;
  cli->discard = (uint8_t)CLI_DISCARD_NONE;
  if (cli->console) {
    write_raw(cli, CLI_PROMPT, sizeof CLI_PROMPT - 1u); /* also after "console on" */
  }
}

void cli_set_console(cli_t *cli, bool on)
{
  cli->console = on;
  cli->esc = 0u;
}

/* ---- console mode (grammar in cli.h) ---- */

enum { ESC_NONE = 0, ESC_START, ESC_CSI, ESC_SS3 };

/* Erase n characters left of the cursor. */
static void rub_out(cli_t *cli, uint32_t n)
{
  static const char k_rub[] = "\b \b\b \b\b \b\b \b\b \b\b \b\b \b\b \b"; /* 8 of them */
  while (n > 0u) {
    const uint32_t k = (n > 8u) ? 8u : n;
    write_raw(cli, k_rub, 3u * (size_t)k);
    n -= k;
  }
}

static void drop_line(cli_t *cli)
{
  cli->len = 0u;
  cli->discard = (uint8_t)CLI_DISCARD_NONE;
}

static void recall_last(cli_t *cli)
{
  rub_out(cli, cli->len);
  memcpy(cli->line, cli->last, cli->last_len);
  drop_line(cli);
  cli->len = cli->last_len;
  if (cli->len > 0u) { /* Up before any line was run: nothing to bring back */
    write_raw(cli, cli->line, cli->len);
  }
}

/* An escape sequence in progress takes ch; false: ch ended it without being part of it
 * (a control byte), to be handled as usual. */
static bool escape_byte(cli_t *cli, uint8_t ch)
{
  const uint8_t st = cli->esc;
  cli->esc = (uint8_t)ESC_NONE;
  if (ch < 0x20u || ch >= 0x7Fu) {
    return false;
  }
  if (st == (uint8_t)ESC_START) {
    if (ch == '[') {
      cli->esc = (uint8_t)ESC_CSI;
    } else if (ch == 'O') {
      cli->esc = (uint8_t)ESC_SS3;
    }
    return true; /* else ESC x (Alt-x): both consumed */
  }
  if (st == (uint8_t)ESC_CSI && ch < 0x40u) {
    cli->esc = (uint8_t)ESC_CSI; /* parameter or intermediate byte */
    return true;
  }
  if (ch == 'A') {
    recall_last(cli); /* Up: ESC [ A, ESC [ 1 ; 5 A, ESC O A */
  }
  return true;
}

static void console_byte(cli_t *cli, uint8_t ch)
{
  if (cli->esc != (uint8_t)ESC_NONE && escape_byte(cli, ch)) {
    return;
  }
  if (ch == 0x1Bu) {
    cli->esc = (uint8_t)ESC_START;
  } else if (ch == 0x08u || ch == 0x7Fu) { /* Ctrl-H, Backspace/DEL */
    if (cli->len > 0u) {
      cli->len--;
      rub_out(cli, 1u);
    }
  } else if (ch == 0x15u) { /* Ctrl-U */
    rub_out(cli, cli->len);
    drop_line(cli);
  } else if (ch == 0x03u) { /* Ctrl-C */
    drop_line(cli);
    write_raw(cli, "^C\r\n" CLI_PROMPT, 4u + sizeof CLI_PROMPT - 1u);
  } else if (ch == '\t' || (ch >= 0x20u && ch <= 0x7Eu)) {
    if (cli->len >= CLI_LINE_MAX) {
      write_raw(cli, "\a", 1u);
    } else {
      const char c = (ch == '\t') ? ' ' : (char)ch;
      cli->line[cli->len++] = c;
      write_raw(cli, &c, 1u);
    }
  }
  /* any other byte: ignored */
}

static void console_eol(cli_t *cli)
{
  cli->esc = (uint8_t)ESC_NONE;
  write_raw(cli, "\r\n", 2u);
  if (cli->discard == (uint8_t)CLI_DISCARD_NONE && cli->len > 0u) {
    bool blank = true;
    for (uint32_t i = 0; i < cli->len; i++) {
      blank = blank && is_wsp(cli->line[i]);
    }
    if (!blank) {
      memcpy(cli->last, cli->line, cli->len);
      cli->last_len = cli->len;
    }
  }
  end_of_line(cli);
}

void cli_rx_lost(cli_t *cli)
{
  cli->discard = (uint8_t)CLI_DISCARD_OVERFLOW; /* also a line lost from its start */
  cli->rx_overflows++;
}

void cli_feed(cli_t *cli, const uint8_t *data, size_t len)
{
  while (len > 0u) {
    const size_t n = cli_feed_line(cli, data, len);
    data += n;
    len -= n;
  }
}

size_t cli_feed_line(cli_t *cli, const uint8_t *data, size_t len)
{
  for (size_t i = 0; i < len; i++) {
    const uint8_t ch = data[i];
    if (ch == '\r' || ch == '\n') {
      const bool lf_of_crlf = (ch == '\n' && cli->after_cr);
      cli->after_cr = (ch == '\r');
      if (!cli->console) {
        end_of_line(cli);
      } else if (!lf_of_crlf) {
        console_eol(cli);
      }
      return i + 1u;
    }
    cli->after_cr = false;
    if (cli->console) {
      console_byte(cli, ch);
      return i + 1u; /* one byte at a time: the caller checks for room before each echo */
    }
    if (cli->discard != (uint8_t)CLI_DISCARD_NONE) {
      continue;
    }
    if (!((ch >= 0x20u && ch <= 0x7Eu) || ch == '\t')) {
      cli->discard = (uint8_t)CLI_DISCARD_BADCHAR;
    } else if (cli->len >= CLI_LINE_MAX) {
      cli->discard = (uint8_t)CLI_DISCARD_TOOLONG;
    } else {
      cli->line[cli->len++] = (char)ch;
    }
  }
  return len;
}
