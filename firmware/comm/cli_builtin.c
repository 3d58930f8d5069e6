#include "comm/cli_builtin.h"

#include <string.h>

#include "comm/numparse.h"
#include "params/fw_version.h"

static void put_value(cli_t *cli, param_idx_t i, param_value_t v)
{
  if (param_info(i)->type == (uint8_t)PARAM_T_F32) {
    cli_put_f32(cli, v.f);
  } else {
    cli_put_u32(cli, v.u);
  }
}

/* "[min,max]" or "{a,b,...}" */
static void put_range(cli_t *cli, param_idx_t i)
{
  const param_info_t *pi = param_info(i);
  if (pi->type == (uint8_t)PARAM_T_ENUM) {
    cli_put(cli, "{");
    bool first = true;
    for (uint32_t v = 0; v < 32u; v++) {
      if ((pi->choices & (1u << v)) != 0u) {
        if (!first) {
          cli_put(cli, ",");
        }
        cli_put_u32(cli, v);
        first = false;
      }
    }
    cli_put(cli, "}");
    return;
  }
  cli_put(cli, "[");
  put_value(cli, i, pi->min);
  cli_put(cli, ",");
  put_value(cli, i, pi->max);
  cli_put(cli, "]");
}

static void put_flags(cli_t *cli, uint8_t flags)
{
  const char *letters[4] = {"P", "L", "R", "B"};
  const uint8_t bits[4] = {PF_PERSIST, PF_LIVE, PF_READONLY, PF_RESTART};
  bool any = false;
  for (unsigned k = 0; k < 4u; k++) {
    if ((flags & bits[k]) != 0u) {
      cli_put(cli, letters[k]);
      any = true;
    }
  }
  if (!any) {
    cli_put(cli, "-");
  }
}

static param_idx_t lookup_arg(cli_t *cli, const char *name)
{
  const param_idx_t i = param_lookup(name, strlen(name));
  if (i == PARAM_COUNT) {
    cli_putf(cli, "unknown parameter '%s'; try list", name);
    cli_emit_err(cli, "NAME");
  }
  return i;
}

static void cmd_help(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: help");
    return;
  }
  const uint32_t n = cli_cmd_count(cli);
  for (uint32_t i = 0; i < n; i++) {
    const cli_cmd_t *c = cli_cmd_at(cli, i);
    const bool has_args = c->args != NULL && c->args[0] != '\0';
    cli_putf(cli, "%s%s%s : %s", c->name, has_args ? " " : "", has_args ? c->args : "", c->help);
    cli_emit_data(cli);
  }
  cli_putf(cli, "%u commands", n);
  cli_emit_ok(cli);
}

static void cmd_list(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  if (argc > 2u) {
    cli_err(cli, "ARGS", "usage: list [PREFIX]");
    return;
  }
  const char *prefix = (argc == 2u) ? argv[1] : "";
  const size_t plen = strlen(prefix);
  const param_values_t *cur = params_current(cli->cfg.params);
  uint32_t n = 0u;
  for (unsigned k = 0; k < (unsigned)PARAM_COUNT; k++) {
    const param_idx_t i = (param_idx_t)k;
    const param_info_t *pi = param_info(i);
    if (strncmp(pi->name, prefix, plen) != 0) {
      continue;
    }
    cli_putf(cli, "%s ", pi->name);
    put_value(cli, i, param_get(cur, i));
    cli_putf(cli, " %s ", pi->unit);
    put_range(cli, i);
    cli_put(cli, " def=");
    put_value(cli, i, pi->def);
    cli_put(cli, " flags=");
    put_flags(cli, pi->flags);
    cli_putf(cli, " %s", pi->help);
    cli_emit_data(cli);
    n++;
  }
  cli_putf(cli, "%u parameters", n);
  cli_emit_ok(cli);
}

static void cmd_get(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  if (argc != 2u) {
    cli_err(cli, "ARGS", "usage: get NAME");
    return;
  }
  const param_idx_t i = lookup_arg(cli, argv[1]);
  if (i == PARAM_COUNT) {
    return;
  }
  const param_info_t *pi = param_info(i);
  cli_putf(cli, "%s ", pi->name);
  put_value(cli, i, param_get(params_current(cli->cfg.params), i));
  cli_putf(cli, " %s", pi->unit);
  cli_emit_ok(cli);
}

/* "NAME: 'TEXT' WHAT; allowed RANGE UNIT" */
static void value_error(cli_t *cli, const char *code, param_idx_t i, const char *text,
                        const char *what)
{
  const param_info_t *pi = param_info(i);
  cli_putf(cli, "%s: '%s' %s; allowed ", pi->name, text, what);
  put_range(cli, i);
  if (strcmp(pi->unit, "-") != 0) {
    cli_putf(cli, " %s", pi->unit);
  }
  cli_emit_err(cli, code);
}

/* Parse and stage one NAME VALUE pair; on failure reply and return false. */
static bool stage_pair(cli_t *cli, const char *name, const char *text)
{
  params_t *p = cli->cfg.params;
  const param_idx_t i = lookup_arg(cli, name);
  if (i == PARAM_COUNT) {
    return false;
  }
  const param_info_t *pi = param_info(i);
  if ((pi->flags & PF_READONLY) != 0u) {
    cli_putf(cli, "%s is read-only", pi->name);
    cli_emit_err(cli, "RO");
    return false;
  }
  param_value_t v = {.u = 0u};
  const numparse_status_t ns = (pi->type == (uint8_t)PARAM_T_F32)
                                   ? numparse_f32(text, strlen(text), &v.f)
                                   : numparse_u32(text, strlen(text), &v.u);
  if (ns == NUMPARSE_ERR_RANGE) {
    value_error(cli, "RANGE", i, text, "is out of range");
    return false;
  }
  if (ns != NUMPARSE_OK) {
    value_error(cli, "VALUE", i, text,
                (pi->type == (uint8_t)PARAM_T_F32) ? "is not a number"
                                                   : "is not an unsigned integer");
    return false;
  }
  const param_status_t st = params_stage(p, i, v);
  if (st != PARAM_OK) {
    value_error(cli, "RANGE", i, text,
                (st == PARAM_ERR_CHOICE) ? "is not a choice" : "is out of range");
    return false;
  }
  return true;
}

/* Reply to a failed commit. */
static void commit_error(cli_t *cli, param_status_t st, const params_err_t *err)
{
  switch (st) {
  case PARAM_ERR_BUSY:
    if (param_info(err->idx) != NULL) {
      cli_putf(cli, "%s cannot change while the drive runs: stop the drive first",
               param_info(err->idx)->name);
    } else {
      cli_put(cli, "drive running: stop the drive first");
    }
    cli_emit_err(cli, "BUSY");
    break;
  case PARAM_ERR_PENDING: cli_err(cli, "PENDING", param_status_str(st)); break;
  case PARAM_ERR_REJECTED:
    cli_err(cli, "REJECTED", (err->why != NULL) ? err->why : param_status_str(st));
    break;
  case PARAM_OK:
  case PARAM_ERR_UNKNOWN:
  case PARAM_ERR_READONLY:
  case PARAM_ERR_RANGE:
  case PARAM_ERR_NOT_FINITE:
  case PARAM_ERR_CHOICE:
  default:
    cli_put(cli, param_status_str(st));
    if (param_info(err->idx) != NULL) {
      cli_putf(cli, ": %s", param_info(err->idx)->name);
    }
    cli_emit_err(cli, "RANGE");
    break;
  }
}

/* A set the application cannot design: which parameters, and its reason. */
static void rejected_set(cli_t *cli, uint32_t argc, const char *const *argv,
                         const params_err_t *err)
{
  for (uint32_t k = 1; k + 1u < argc; k += 2u) {
    cli_putf(cli, "%s %s%s", argv[k], argv[k + 1u], (k + 3u < argc) ? ", " : ": ");
  }
  cli_put(cli, (err->why != NULL) ? err->why : param_status_str(PARAM_ERR_REJECTED));
  cli_emit_err(cli, "REJECTED");
}

static void cmd_set(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  params_t *p = cli->cfg.params;
  if (argc < 3u || (argc % 2u) == 0u) {
    cli_err(cli, "ARGS", "usage: set NAME VALUE [NAME VALUE ...]");
    return;
  }
  params_discard(p);
  for (uint32_t k = 1; k + 1u < argc; k += 2u) {
    if (!stage_pair(cli, argv[k], argv[k + 1u])) {
      params_discard(p);
      return;
    }
  }
  params_err_t err;
  const param_status_t st = params_commit(p, &err);
  if (st == PARAM_ERR_REJECTED) {
    rejected_set(cli, argc, argv, &err);
    return;
  }
  if (st != PARAM_OK) {
    commit_error(cli, st, &err);
    return;
  }
  const param_values_t *cur = params_current(p);
  for (uint32_t k = 1; k + 1u < argc; k += 2u) {
    const param_idx_t i = param_lookup(argv[k], strlen(argv[k]));
    cli_putf(cli, "%s%s ", (k > 1u) ? " " : "", param_info(i)->name);
    put_value(cli, i, param_get(cur, i));
  }
  cli_emit_ok(cli);
}

static void put_slot(cli_t *cli, const param_store_report_t *rep)
{
  cli_putf(cli, " slot %s seq %u", (rep->slot == 0) ? "A" : "B", rep->seq);
}

static void cmd_save(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  const bool force = argc == 2u && strcmp(argv[1], "force") == 0;
  if (argc != 1u && !force) {
    cli_err(cli, "ARGS", "usage: save [force]");
    return;
  }
  if (cli->cfg.store == NULL) {
    cli_err(cli, "NOSTORE", "no parameter store in this build");
    return;
  }
  params_t *p = cli->cfg.params;
  param_store_report_t rep;
  const uint32_t how = (params_loop_safe(p) ? (uint32_t)PARAM_SAVE_LOOP_SAFE : 0u) |
                       (force ? (uint32_t)PARAM_SAVE_FORCE : 0u);
  const param_store_status_t st = param_store_save(cli->cfg.store, params_current(p), how, &rep);
  switch (st) {
  case PARAM_STORE_OK:
  case PARAM_STORE_UNCHANGED:
    cli_put(cli, (st == PARAM_STORE_OK) ? "saved" : "unchanged");
    put_slot(cli, &rep);
    cli_emit_ok(cli);
    break;
  case PARAM_STORE_ERR_BUSY: cli_err(cli, "BUSY", "drive running: stop the drive first"); break;
  case PARAM_STORE_ERR_NEWER:
    cli_err(cli, "FORMAT",
            "the store holds an image of a newer firmware format; "
            "save force overwrites it");
    break;
  case PARAM_STORE_NONE:
  case PARAM_STORE_NEWER:
  case PARAM_STORE_ERR_FLASH:
  case PARAM_STORE_ERR_VERIFY:
  case PARAM_STORE_ERR_CONFIG:
  default:
    cli_putf(cli, "%s; the previous image is kept", param_store_status_str(st));
    cli_emit_err(cli, "FLASH");
    break;
  }
}

static const char *slot_state_str(uint8_t s)
{
  switch ((param_slot_state_t)s) {
  case PARAM_SLOT_EMPTY: return "empty";
  case PARAM_SLOT_VALID: return "valid";
  case PARAM_SLOT_NEWER: return "newer format";
  case PARAM_SLOT_CORRUPT:
  default: return "corrupt";
  }
}

static void apply_all(cli_t *cli, const param_values_t *v, param_status_t *st_out)
{
  params_t *p = cli->cfg.params;
  params_err_t err;
  params_discard(p);
  param_status_t st = params_stage_all(p, v, &err);
  if (st == PARAM_OK) {
    st = params_commit(p, &err);
  } else {
    params_discard(p);
  }
  if (st != PARAM_OK) {
    commit_error(cli, st, &err);
  }
  *st_out = st;
}

static void cmd_load(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: load");
    return;
  }
  if (cli->cfg.store == NULL) {
    cli_err(cli, "NOSTORE", "no parameter store in this build");
    return;
  }
  param_values_t v = *params_current(cli->cfg.params);
  param_store_report_t rep;
  if (param_store_load(cli->cfg.store, &v, &rep) != PARAM_STORE_OK) {
    cli_putf(cli, "no valid parameter image (slot A %s, slot B %s); nothing changed",
             slot_state_str(rep.slot_state[0]), slot_state_str(rep.slot_state[1]));
    cli_emit_err(cli, "NOSTORE");
    return;
  }
  param_status_t st;
  apply_all(cli, &v, &st);
  if (st != PARAM_OK) {
    return;
  }
  cli_put(cli, "loaded");
  put_slot(cli, &rep);
  cli_putf(cli, " dropped %u rejected %u defaulted %u", rep.dropped, rep.rejected, rep.defaulted);
  cli_emit_ok(cli);
}

static void cmd_defaults(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: defaults");
    return;
  }
  param_values_t v;
  param_values_defaults(&v);
  param_status_t st;
  apply_all(cli, &v, &st);
  if (st == PARAM_OK) {
    cli_ok(cli, "defaults applied (not saved)");
  }
}

static void cmd_diff(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: diff");
    return;
  }
  const param_values_t *cur = params_current(cli->cfg.params);
  uint32_t n = 0u;
  for (unsigned k = 0; k < (unsigned)PARAM_COUNT; k++) {
    const param_idx_t i = (param_idx_t)k;
    const param_info_t *pi = param_info(i);
    const param_value_t v = param_get(cur, i);
    if (param_value_equal(i, v, pi->def)) {
      continue;
    }
    cli_putf(cli, "%s ", pi->name);
    put_value(cli, i, v);
    cli_put(cli, " default ");
    put_value(cli, i, pi->def);
    cli_emit_data(cli);
    n++;
  }
  cli_putf(cli, "%u differ", n);
  cli_emit_ok(cli);
}

static void cmd_version(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  (void)argv;
  if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: version");
    return;
  }
  cli_putf(cli, "fw %s layout %u format %u params %u", fw_version_string(),
           PARAM_LAYOUT_VERSION, PARAM_STORE_FORMAT, (uint32_t)PARAM_COUNT);
  cli_emit_ok(cli);
}

static void cmd_console(cli_t *cli, void *ctx, uint32_t argc, const char *const *argv)
{
  (void)ctx;
  if (argc == 2u && (strcmp(argv[1], "on") == 0 || strcmp(argv[1], "off") == 0)) {
    cli_set_console(cli, argv[1][1] == 'n');
  } else if (argc != 1u) {
    cli_err(cli, "ARGS", "usage: console [on|off]");
    return;
  }
  cli_ok(cli, cli->console ? "console on" : "console off");
}

const cli_cmd_t cli_builtin_cmds[] = {
    {"help", "", "list the commands", cmd_help, NULL},
    {"list", "[PREFIX]", "parameters with value, unit, range, default, flags and help",
     cmd_list, NULL},
    {"get", "NAME", "value of one parameter", cmd_get, NULL},
    {"set", "NAME VALUE [NAME VALUE ...]", "change parameters together (all or nothing)",
     cmd_set, NULL},
    {"save", "[force]",
     "write the persistent parameters to flash (drive stopped; force: "
     "over an image of a newer format)",
     cmd_save, NULL},
    {"load", "", "apply the parameters stored in flash", cmd_load, NULL},
    {"defaults", "", "apply the default parameters (not saved)", cmd_defaults, NULL},
    {"diff", "", "parameters that differ from their defaults", cmd_diff, NULL},
    {"version", "", "firmware and parameter layout versions", cmd_version, NULL},
    {"console", "[on|off]",
     "terminal mode: prompt, echo, line editing (off: machine mode, "
     "the default)",
     cmd_console, NULL},
};

uint32_t cli_builtin_count(void)
{
  return (uint32_t)(sizeof cli_builtin_cmds / sizeof cli_builtin_cmds[0]);
}
