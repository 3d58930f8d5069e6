# Warning sets. Warnings are errors on every preset.
#
# gyro_strict_warnings(target): firmware core and HAL. -Wdouble-promotion keeps the
#   sample path in single precision; -Wconversion catches silent narrowing (float from
#   double, int from float) that costs precision or instructions on the FPv4-SP FPU.
# gyro_host_warnings(target): host simulator, tools and tests, which compute in double
#   on purpose; -Wdouble-promotion and -Wconversion would only add casts there.
set(GYRO_COMMON_WARNINGS -Wall -Wextra -Werror -Wshadow -Wundef -Wpointer-arith
    -Wcast-qual -Wformat=2)
set(GYRO_STRICT_C_WARNINGS ${GYRO_COMMON_WARNINGS} -Wdouble-promotion -Wconversion
    -Wsign-conversion -Wstrict-prototypes -Wmissing-prototypes
    -Wold-style-definition -Wvla -Wswitch-enum)

function(gyro_strict_warnings target)
  target_compile_options(${target} PRIVATE $<$<COMPILE_LANGUAGE:C>:${GYRO_STRICT_C_WARNINGS}>)
endfunction()

function(gyro_host_warnings target)
  target_compile_options(${target} PRIVATE ${GYRO_COMMON_WARNINGS}
    $<$<COMPILE_LANGUAGE:C>:-Wstrict-prototypes -Wvla>)
endfunction()
