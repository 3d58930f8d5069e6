# Size report of one image: cmake -DELF=<elf> -DSIZE_TOOL=<arm-none-eabi-size> -DNAME=<n>
#   -P image_size.cmake
# Sums the sections of `size -A` by region (address ranges of linker/stm32f405.ld, the
# CCM sections and the main stack, which sits in CCM, by name: stm32f405_qemu.ld puts
# CCM at the top of QEMU's SRAM); the
# load images of .data, .ramfunc and .ccm_data count against flash as well.
execute_process(COMMAND ${SIZE_TOOL} -A -d ${ELF} OUTPUT_VARIABLE out RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "size failed on ${ELF}")
endif()
set(boot 0)
set(flash 0)
set(ram 0)
set(ccm 0)
set(stack 0)
string(REPLACE "\n" ";" lines "${out}")
foreach(line ${lines})
  if(line MATCHES "^([.A-Za-z_0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)")
    set(sec ${CMAKE_MATCH_1})
    set(sz ${CMAKE_MATCH_2})
    set(addr ${CMAKE_MATCH_3})
    if(sec STREQUAL ".ccm_data" OR sec STREQUAL ".ccm_bss" OR sec STREQUAL ".stack") # CCM
      math(EXPR ccm "${ccm} + ${sz}")
      if(sec STREQUAL ".stack")
        set(stack ${sz})
      endif()
    elseif(addr GREATER_EQUAL 134217728 AND addr LESS 134234112)    # 0x08000000 + 16K
      math(EXPR boot "${boot} + ${sz}")
    elseif(addr GREATER_EQUAL 134234112 AND addr LESS 135266304)    # .. 0x08100000
      math(EXPR flash "${flash} + ${sz}")
    elseif(addr GREATER_EQUAL 536870912 AND addr LESS 537001984)    # 0x20000000 + 128K
      math(EXPR ram "${ram} + ${sz}")
    elseif(addr GREATER_EQUAL 268435456 AND addr LESS 268500992)    # 0x10000000 + 64K
      math(EXPR ccm "${ccm} + ${sz}")
    endif()
    if(sec STREQUAL ".data" OR sec STREQUAL ".ramfunc" OR sec STREQUAL ".ccm_data")
      math(EXPR flash "${flash} + ${sz}")
    endif()
  endif()
endforeach()
function(pct used total out)
  math(EXPR p10 "(${used} * 1000 + ${total} / 2) / ${total}")
  math(EXPR whole "${p10} / 10")
  math(EXPR frac "${p10} % 10")
  set(${out} "${whole}.${frac} %" PARENT_SCOPE)
endfunction()
pct(${boot} 16384 boot_pct)
pct(${flash} 999424 flash_pct)
pct(${ram} 131072 ram_pct)
pct(${ccm} 65536 ccm_pct)
message(STATUS "size report ${NAME}:")
message(STATUS "  flash boot (sector 0)   ${boot} / 16384 B (${boot_pct})")
message(STATUS "  flash code (sector 3-)  ${flash} / 999424 B (${flash_pct})")
message(STATUS "  flash param (sectors 1-2) 32768 B reserved")
message(STATUS "  SRAM                    ${ram} / 131072 B (${ram_pct})")
message(STATUS "  CCM                     ${ccm} / 65536 B (${ccm_pct}; main stack ${stack} B)")
