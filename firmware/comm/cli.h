/* Text command line on the tuning UART (thesis 7.3: parameters are read and written over
 * the serial port while the gyro runs). Fed bytes by the background loop, never by the
 * ISR; all replies go through one output callback.
 *
 * Input grammar
 *   line    = *WSP [ word *( 1*WSP word ) ] *WSP EOL
 *   EOL     = CR | LF | CR LF      (an empty or blank line, e.g. the LF of CR LF, is
 *                                   ignored without a reply)
 *   WSP     = SP | HTAB
 *   word    = 1*( %x21-7E )
 *   - at most CLI_LINE_MAX bytes before the EOL; a longer line is discarded whole and
 *     answered "err TOOLONG ..." when its EOL arrives;
 *   - any other byte (NUL, control characters, DEL, bytes >= 0x80) discards the whole
 *     line, answered "err BADCHAR ..." at its EOL;
 *   - received bytes lost (cli_rx_lost: the UART's RX ring overflowed) discard the line
 *     in progress, answered "err OVERFLOW ..." at the next EOL: a line missing bytes is
 *     never executed; the losses are counted (rx_overflows);
 *   - no echo, no prompt, no line editing; names are case-sensitive.
 *   This is machine mode, the default, for programs (gyroctl, scripts).
 *
 * Console mode ("console on", for a person at a terminal: picocom, minicom, screen,
 * PuTTY; "console off" goes back; not persisted, every start is in machine mode)
 *   - a prompt CLI_PROMPT after every reply (and after "console on");
 *   - printable bytes are echoed; a tab is taken and echoed as a space; at CLI_LINE_MAX
 *     bytes further ones are refused with BEL (no TOOLONG);
 *   - BS (Ctrl-H) and DEL erase the last byte ("\b \b"); Ctrl-U erases the line;
 *     Ctrl-C drops the line ("^C", a new prompt);
 *   - escape sequences (ESC [ ... final, ESC O x, ESC x: arrow and function keys) are
 *     consumed without a reply; Up (ESC [ A, ESC O A) brings back the last line run;
 *   - other control bytes and bytes >= 0x80 are ignored (no BADCHAR);
 *   - CR, LF or CR LF ends the line: "\r\n" is echoed, then the reply as in machine
 *     mode, then the prompt; a blank line gives a new prompt only;
 *   - lost input still discards the line (err OVERFLOW);
 *   - cli_feed_line takes one byte at a time, so the application checks for TX room
 *     before each echo.
 *   Echo, prompt and replies all go through the one output callback, never a byte
 *   written in between by anyone else: telemetry frames stay whole.
 *
 * Reply grammar: every non-blank line gets exactly one reply,
 *   reply   = *data-line final
 *   data-line = "- " text CRLF        (list, diff, help: one item per line)
 *   final   = "ok" [ SP text ] CRLF
 *           | "err" SP CODE SP message CRLF
 *   CODE    = ARGS | UNKNOWN | NAME | RO | VALUE | RANGE | BUSY | PENDING | REJECTED |
 *             NOSTORE | FLASH | FORMAT | TOOLONG | BADCHAR | OVERFLOW | INTERNAL
 *             (application handlers may add their own upper-case codes)
 *   text never contains CR or LF; a host reads lines until one starts with "ok" or "err".
 *
 * Built-in commands and their final lines
 *   help                    - NAME ARGS : HELP ...            ok N commands
 *   list [PREFIX]           - NAME VALUE UNIT RANGE def=DEFAULT flags=FLAGS HELP ...
 *                           ok N parameters
 *       RANGE is [MIN,MAX] or {A,B,...} for a choice; FLAGS letters: P persistent,
 *       L live (may change while the drive runs), R read-only, B applies after a
 *       restart (boot), "-" none; UNIT "-" for dimensionless; HELP is the rest.
 *   get NAME                ok NAME VALUE UNIT
 *   set NAME VALUE [NAME VALUE ...]
 *                           ok NAME VALUE [NAME VALUE ...]   (values as now held)
 *       all pairs are validated, staged and published together at one tick boundary,
 *       or nothing changes; a bad value is answered with the allowed range.
 *   save [force]            ok saved slot A|B seq N  |  ok unchanged slot A|B seq N
 *       refused (err FORMAT) while the store holds an image of a newer format, which
 *       this firmware cannot read; "save force" overwrites it.
 *   load                    ok loaded slot A|B seq N dropped D rejected R defaulted M
 *   defaults                ok defaults applied (not saved)
 *   diff                    - NAME VALUE default DEFAULT ...  ok N differ
 *   version                 ok fw MAJOR.MINOR.PATCH layout L format F params N
 * plus the application's registered commands (status, sweep, stream FIELD... @RATE_HZ,
 * stop, ...), listed by help.
 *
 * The output callback receives whole lines (CRLF included) and must take all of them:
 * the application queues them (a TX ring sized for the longest reply, about 5 KB for
 * list) or drains the UART; the CLI keeps no output backlog. An application that feeds
 * one line at a time (cli_feed_line) can wait in the background for room in its TX ring
 * before the next line, so no reply is ever cut.
 */
#ifndef CLI_H
#define CLI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "params/param_store.h"
#include "params/params.h"

#define CLI_LINE_MAX 120u
#define CLI_MAX_ARGS 16u
#define CLI_MAX_APP_CMDS 8u
#define CLI_OUT_MAX 256u
#define CLI_PROMPT "gyro> "

typedef struct cli cli_t;

typedef void (*cli_write_fn)(void *ctx, const char *data, size_t len);
/* argv[0] is the command name; every argv[i] is a NUL-terminated word. A handler ends
 * with exactly one cli_ok/cli_err (or cli_emit_ok/cli_emit_err); missing that, the CLI
 * answers "err INTERNAL"; output after the final line is dropped. */
typedef void (*cli_handler_fn)(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv);

typedef struct {
  const char *name; /* one word */
  const char *args; /* usage, e.g. "FIELD... @RATE_HZ" ("" if none) */
  const char *help; /* one line */
  cli_handler_fn fn;
  void *ctx;
} cli_cmd_t;

typedef struct {
  params_t *params;     /* required */
  param_store_t *store; /* NULL: save/load answer err NOSTORE */
  cli_write_fn write;   /* required */
  void *write_ctx;
  /* Commands found before the registered ones, listed first by help: the parameter
   * commands (comm/cli_builtin.h), given here so that the line discipline does not
   * depend on them. NULL (n_builtin 0): none. */
  const cli_cmd_t *builtin;
  uint32_t n_builtin;
} cli_cfg_t;

typedef enum {
  CLI_DISCARD_NONE = 0,
  CLI_DISCARD_TOOLONG,
  CLI_DISCARD_BADCHAR,
  CLI_DISCARD_OVERFLOW
} cli_discard_t;

struct cli {
  cli_cfg_t cfg;
  const cli_cmd_t *app[CLI_MAX_APP_CMDS];
  uint32_t n_app;
  char line[CLI_LINE_MAX + 1u];
  uint32_t len;
  uint8_t discard; /* cli_discard_t of the line being received */
  bool replied;    /* final line sent for the current command */
  char out[CLI_OUT_MAX];
  uint32_t out_len;
  uint32_t truncated;    /* reply lines cut at CLI_OUT_MAX (should stay 0) */
  uint32_t rx_overflows; /* input losses reported by cli_rx_lost */
  bool console;          /* console mode (prompt, echo, editing); false: machine mode */
  bool after_cr;         /* the last EOL byte was CR: an LF right after it belongs to it */
  uint8_t esc;           /* console: state of an escape sequence being consumed */
  uint32_t last_len;     /* console: the last line run, for Up */
  char last[CLI_LINE_MAX + 1u];
};

/* Returns 0, or -1 for a missing params/write. */
int cli_init(cli_t *cli, const cli_cfg_t *cfg);
/* Register an application command (kept by pointer). Returns 0, or -1 if the table is
 * full, the name is empty, not one word, or already taken, or fn is NULL. */
int cli_register(cli_t *cli, const cli_cmd_t *cmd);
/* Every command, built-in ones first then the registered ones in order, for help. */
uint32_t cli_cmd_count(const cli_t *cli);
const cli_cmd_t *cli_cmd_at(const cli_t *cli, uint32_t i); /* NULL past the end */
/* Feed received bytes; complete lines are executed and answered before it returns. */
void cli_feed(cli_t *cli, const uint8_t *data, size_t len);
/* Feed bytes up to and including the first EOL (executed and answered); returns the
 * number taken (len if there is no EOL). In console mode it takes one byte (its echo
 * written) per call. */
size_t cli_feed_line(cli_t *cli, const uint8_t *data, size_t len);
/* Bytes were lost after the last byte fed: discard the line in progress (err OVERFLOW
 * at its EOL) and count the loss. */
void cli_rx_lost(cli_t *cli);
/* Machine mode (false, the default) or console mode (true); the command "console". */
void cli_set_console(cli_t *cli, bool on);

/* Reply building for handlers: append to the pending line, then emit it. Characters
 * outside %x20-7E are replaced by '?', so a reply is always one line. */
void cli_put(cli_t *cli, const char *s);
void cli_put_n(cli_t *cli, const char *s, size_t n);
void cli_put_f32(cli_t *cli, float x);
void cli_put_u32(cli_t *cli, uint32_t x);
/* Formatted append, without printf: cli_putf(cli, "fields %u at %f Hz: %s", n, rate_hz, why)
 * appends the format with each conversion replaced by the next argument:
 *   %s  a string (const char *; NULL appends nothing), as cli_put
 *   %u  an integer in [0, 2^32 - 1], as cli_put_u32
 *   %d  an integer in [-2^31, 2^31 - 1], with a '-' when negative
 *   %f  a float, as cli_put_f32 (the shortest text that reads back to the same float)
 *   %%  one '%'
 * 1 to CLI_PUTF_MAX_ARGS arguments; each one's type picks its kind at compile time
 * (cli_arg_t, CLI_ARG): a float, a string, or any integer type; a double does not
 * compile (single precision on the target: cast it where it is meant). A conversion
 * whose argument is of another kind or out of its range, an unknown conversion or a
 * missing argument appends '?', so a mistake shows in the reply (unit-tested). The
 * output is bounded as every append is (CLI_OUT_MAX). */
#define CLI_PUTF_MAX_ARGS 12u

typedef struct {
  uint8_t kind; /* 's', 'i' or 'f' */
  const char *s;
  int64_t i;
  float f;
} cli_arg_t;

static inline cli_arg_t cli_arg_str(const char *s) { return (cli_arg_t){.kind = 's', .s = s}; }
static inline cli_arg_t cli_arg_int(int64_t i) { return (cli_arg_t){.kind = 'i', .i = i}; }
static inline cli_arg_t cli_arg_f32(float f) { return (cli_arg_t){.kind = 'f', .f = f}; }
/* Declared, never defined: an argument of a type without a kind (double, a struct) has no
 * conversion to this parameter and does not compile. */
struct cli_arg_no_kind;
cli_arg_t cli_arg_refused(struct cli_arg_no_kind *refused);

#define CLI_ARG(x) \
  _Generic((x), float: cli_arg_f32, double: cli_arg_refused, long double: cli_arg_refused, \
           char *: cli_arg_str, const char *: cli_arg_str, default: cli_arg_int)(x)

void cli_putf_args(cli_t *cli, const char *fmt, const cli_arg_t *args, uint32_t n);

/* clang-format off */
#define CLI_NARG_(_1, _2, _3, _4, _5, _6, _7, _8, _9, _10, _11, _12, N, ...) N
#define CLI_NARG(...) CLI_NARG_(__VA_ARGS__, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0)
#define CLI_MAP_1(x) CLI_ARG(x)
#define CLI_MAP_2(x, ...) CLI_ARG(x), CLI_MAP_1(__VA_ARGS__)
#define CLI_MAP_3(x, ...) CLI_ARG(x), CLI_MAP_2(__VA_ARGS__)
#define CLI_MAP_4(x, ...) CLI_ARG(x), CLI_MAP_3(__VA_ARGS__)
#define CLI_MAP_5(x, ...) CLI_ARG(x), CLI_MAP_4(__VA_ARGS__)
#define CLI_MAP_6(x, ...) CLI_ARG(x), CLI_MAP_5(__VA_ARGS__)
#define CLI_MAP_7(x, ...) CLI_ARG(x), CLI_MAP_6(__VA_ARGS__)
#define CLI_MAP_8(x, ...) CLI_ARG(x), CLI_MAP_7(__VA_ARGS__)
#define CLI_MAP_9(x, ...) CLI_ARG(x), CLI_MAP_8(__VA_ARGS__)
#define CLI_MAP_10(x, ...) CLI_ARG(x), CLI_MAP_9(__VA_ARGS__)
#define CLI_MAP_11(x, ...) CLI_ARG(x), CLI_MAP_10(__VA_ARGS__)
#define CLI_MAP_12(x, ...) CLI_ARG(x), CLI_MAP_11(__VA_ARGS__)
#define CLI_CAT_(a, b) a##b
#define CLI_CAT(a, b) CLI_CAT_(a, b)
#define cli_putf(cli, fmt, ...)                                                                  \
  cli_putf_args((cli), (fmt), (const cli_arg_t[]){CLI_CAT(CLI_MAP_, CLI_NARG(__VA_ARGS__))(__VA_ARGS__)}, \
                (uint32_t)CLI_NARG(__VA_ARGS__))
/* clang-format on */

void cli_emit_data(cli_t *cli); /* "- " text */
/* One "- KEY VALUE" data line (status-style key/value reports). */
void cli_data_u32(cli_t *cli, const char *key, uint32_t v);
void cli_data_f32(cli_t *cli, const char *key, float v);
void cli_emit_ok(cli_t *cli);                    /* "ok" [" " text], final */
void cli_emit_err(cli_t *cli, const char *code); /* "err CODE " text, final */
void cli_ok(cli_t *cli, const char *msg);        /* msg may be NULL */
void cli_err(cli_t *cli, const char *code, const char *msg);

#endif /* CLI_H */
