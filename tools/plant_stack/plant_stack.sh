#!/bin/sh
# Stack frames of the host plant (host_sim/plant) cross-compiled for the Cortex-M4F
# target (arm-none-eabi-gcc, newlib headers, the project's host warning set as errors),
# and the deepest call chains from plant_init and plant_step (library calls such as
# libm and vsnprintf not counted). Usage: tools/plant_stack/plant_stack.sh [N largest]
set -e
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
OUT=$(mktemp -d)
cd "$OUT"
for f in "$ROOT"/host_sim/plant/*.c; do
  arm-none-eabi-gcc -std=c11 -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -O2 \
    -ffunction-sections -fdata-sections -fno-common -Wall -Wextra -Werror -Wshadow -Wundef \
    -Wpointer-arith -Wcast-qual -Wformat=2 -Wstrict-prototypes -Wvla -D_DEFAULT_SOURCE \
    -fstack-usage -fcallgraph-info=su -I"$ROOT"/host_sim -I"$ROOT"/hal/include -I"$ROOT"/hal/boards/ref_f405/include \
    -c "$f" -o "$(basename "$f" .c).o"
done
echo "largest frames (bytes):"
cat ./*.su | sed "s|$ROOT/host_sim/plant/||" | sort -t"$(printf '\t')" -k2 -n -r | head -"${1:-12}"
echo "deepest chains:"
python3 "$ROOT"/tools/plant_stack/stack_chain.py "$ROOT" plant_init plant_step
rm -rf "$OUT"
