/* Firmware identity, reported by the `version` command and stored in parameter images.
 * It sits beside the parameter store, the lowest layer that needs it, so that the store
 * and the command line above it include it without a cycle between folders. */
#ifndef FW_VERSION_H
#define FW_VERSION_H

#include <stdint.h>

/* "MAJOR.MINOR.PATCH", from the CMake project version. */
const char *fw_version_string(void);
/* MAJOR << 16 | MINOR << 8 | PATCH */
uint32_t fw_version_number(void);

#endif /* FW_VERSION_H */
