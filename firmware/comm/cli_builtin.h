/* Built-in commands of the command line (help, list, get, set, save, load, defaults,
 * diff, version, console): thin wrappers over params and param_store. Reply formats in cli.h. */
#ifndef CLI_BUILTIN_H
#define CLI_BUILTIN_H

#include <stdint.h>

#include "comm/cli.h"

/* NULL if name is not a built-in command. */
const cli_cmd_t *cli_builtin_find(const char *name);
uint32_t cli_builtin_count(void);
const cli_cmd_t *cli_builtin_at(uint32_t i);

#endif /* CLI_BUILTIN_H */
