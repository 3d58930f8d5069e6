# gyro_add_image(<name> SOURCES <src>... LIBS <lib>... [LINKER_SCRIPT <file>]
#                [STACK_BYTES <n>])
#
# One firmware image for the Cortex-M4F board: links SOURCES and LIBS with the board's
# linker script (default linker/stm32f405.ld) into <name>.elf, writes <name>.map,
# <name>.bin (raw from 0x0800_0000; it spans the parameter sectors, filled with 0xFF)
# and <name>.hex (sparse: leaves the parameter sectors alone) next to it, and prints
# a size report at build time: the linker's per-region table (--print-memory-usage)
# followed by flash / SRAM / CCM used vs available (linker/image_size.cmake). The link
# fails when a function of the sample interrupt's path lies outside SRAM
# (linker/check_ramfunc.py: GYRO_RAMFUNC, firmware/dsp/ramfunc.h).
# Compiler and linker warnings are errors.
set(GYRO_DEFAULT_LINKER_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/stm32f405.ld)
# Images that run in QEMU's netduinoplus2 (no CCM there: stm32f405_qemu.ld).
set(GYRO_QEMU_LINKER_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/stm32f405_qemu.ld)
set(GYRO_LINKER_SECTIONS ${CMAKE_CURRENT_LIST_DIR}/stm32f405_sections.ld)
set(GYRO_IMAGE_SIZE_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/image_size.cmake)
# The post-link check that the sample interrupt's path runs from SRAM (check_ramfunc.py).
set(GYRO_RAMFUNC_CHECK ${CMAKE_CURRENT_LIST_DIR}/check_ramfunc.py)
find_package(Python3 REQUIRED COMPONENTS Interpreter)

function(gyro_add_image name)
  cmake_parse_arguments(IMG "" "LINKER_SCRIPT;STACK_BYTES" "SOURCES;LIBS" ${ARGN})
  if(NOT IMG_SOURCES)
    message(FATAL_ERROR "gyro_add_image(${name}): SOURCES is required")
  endif()
  if(NOT IMG_LINKER_SCRIPT)
    set(IMG_LINKER_SCRIPT ${GYRO_DEFAULT_LINKER_SCRIPT})
  endif()
  add_executable(${name} ${IMG_SOURCES})
  set_target_properties(${name} PROPERTIES SUFFIX ".elf"
    LINK_DEPENDS "${IMG_LINKER_SCRIPT};${GYRO_LINKER_SECTIONS}")
  target_link_libraries(${name} PRIVATE ${IMG_LIBS})
  gyro_strict_warnings(${name})
  target_link_options(${name} PRIVATE
    -T${IMG_LINKER_SCRIPT}
    -L${CMAKE_CURRENT_FUNCTION_LIST_DIR}
    -Wl,-Map=${CMAKE_CURRENT_BINARY_DIR}/${name}.map,--cref
    -Wl,--print-memory-usage
    -Wl,--fatal-warnings
    # .ramfunc makes the SRAM segment writable and executable on purpose.
    -Wl,--no-warn-rwx-segments)
  if(IMG_STACK_BYTES)
    # the main stack's size (stm32f405_sections.ld; 8 KB unless given)
    target_link_options(${name} PRIVATE -Wl,--defsym=__gyro_stack_size=${IMG_STACK_BYTES})
  endif()
  add_custom_command(TARGET ${name} POST_BUILD
    COMMAND ${Python3_EXECUTABLE} ${GYRO_RAMFUNC_CHECK} --elf $<TARGET_FILE:${name}>
            --map ${name}.map --objdump ${CMAKE_OBJDUMP}
    COMMAND ${CMAKE_OBJCOPY} -O binary --gap-fill 0xff $<TARGET_FILE:${name}> ${name}.bin
    COMMAND ${CMAKE_OBJCOPY} -O ihex $<TARGET_FILE:${name}> ${name}.hex
    COMMAND ${CMAKE_COMMAND} -DELF=$<TARGET_FILE:${name}> -DSIZE_TOOL=${CMAKE_SIZE}
            -DNAME=${name} -P ${GYRO_IMAGE_SIZE_SCRIPT}
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
    BYPRODUCTS ${CMAKE_CURRENT_BINARY_DIR}/${name}.bin ${CMAKE_CURRENT_BINARY_DIR}/${name}.hex
               ${CMAKE_CURRENT_BINARY_DIR}/${name}.map
    VERBATIM)
endfunction()
