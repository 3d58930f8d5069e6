#include "params/fw_version.h"

#ifndef GYRO_FW_VERSION_MAJOR
#error "GYRO_FW_VERSION_MAJOR/MINOR/PATCH come from the CMake project version"
#endif

#define FW_STR2(x) #x
#define FW_STR(x) FW_STR2(x)

const char *fw_version_string(void)
{
  return FW_STR(GYRO_FW_VERSION_MAJOR) "." FW_STR(GYRO_FW_VERSION_MINOR) "." FW_STR(
      GYRO_FW_VERSION_PATCH);
}

uint32_t fw_version_number(void)
{
  return ((uint32_t)GYRO_FW_VERSION_MAJOR << 16) | ((uint32_t)GYRO_FW_VERSION_MINOR << 8) |
         (uint32_t)GYRO_FW_VERSION_PATCH;
}
