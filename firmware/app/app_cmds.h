/* The application's own commands on the command line (the parameter commands are
 * built into comm/cli): status, drive on|off. */
#ifndef APP_CMDS_H
#define APP_CMDS_H


#include "app/app_core.h"

/* Register the commands with a->cli. Returns 0, or -1 if the table is full. */
int app_cmds_register(app_t *a);

#endif /* APP_CMDS_H */
