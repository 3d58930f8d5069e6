/* Built-in commands of the command line (help, list, get, set, save, load, defaults,
 * diff, version, console): thin wrappers over params and param_store. Reply formats in cli.h. */
#ifndef CLI_BUILTIN_H
#define CLI_BUILTIN_H

#include <stdint.h>

#include "comm/cli.h"

/* The built-in command rows, for cli_cfg_t's builtin / n_builtin:
 *   const cli_cfg_t cc = {params, store, write, ctx, cli_builtin_cmds, cli_builtin_count()}; */
extern const cli_cmd_t cli_builtin_cmds[];
uint32_t cli_builtin_count(void);

#endif /* CLI_BUILTIN_H */
