#!/usr/bin/env python3
"""Post-link check of a target image: the sample interrupt's path runs from SRAM.

    check_ramfunc.py --elf IMAGE.elf --map IMAGE.map [--entry app_sample_isr]

Fails (exit 1) when
  - a function from a .ramfunc input section (GYRO_RAMFUNC, firmware/dsp/ramfunc.h, and
    the HAL's STM32F4_RAMFUNC) lies outside the RAM region of the map's memory
    configuration, or
  - the interrupt entry (--entry, when the image has it) lies outside RAM, or
  - a function that SRAM code calls directly (BL or B to the start of a function, veneers
    resolved to their target) lies outside RAM, unless it is one of the entry's calls
    off the sample path (OFF_PATH: a design change, a queued request), which only the
    entry may make.
A function of the sample path that lost its GYRO_RAMFUNC is then called from SRAM code
and found in flash: the build stops instead of the interrupt running past its cycle
budget (tools/bench/README.md).
"""
import argparse
import re
import subprocess
import sys

# What the interrupt entry calls besides the sample path, in flash by design: a new
# design (gyro_apply) and a queued request (what take_request calls), both through
# take_changes (app.c), at most once per interrupt and rare.
OFF_PATH = {"take_changes"}


def memory_region(map_text, name):
    m = re.search(r"^%s\s+0x([0-9a-fA-F]+)\s+0x([0-9a-fA-F]+)" % re.escape(name), map_text, re.M)
    if not m:
        raise SystemExit(f"check_ramfunc: no memory region {name} in the map")
    lo = int(m.group(1), 16)
    return lo, lo + int(m.group(2), 16)


def functions(objdump, elf):
    """name -> (address, output section) of every function symbol."""
    out = subprocess.run([objdump, "-t", elf], capture_output=True, text=True, check=True).stdout
    funcs = {}
    for line in out.splitlines():
        # 20002688 g     F .ramfunc	000001a4 gyro_tick
        m = re.match(r"^([0-9a-f]+) (.{7}) (\S+)\s+[0-9a-f]+\s+(\S+)$", line)
        if m and m.group(2).endswith("F"):
            funcs[m.group(4)] = (int(m.group(1), 16) & ~1, m.group(3))
    return funcs


def calls(objdump, elf, lo, hi):
    """(caller, callee name) for every direct branch to a symbol in code within [lo, hi)."""
    out = subprocess.run([objdump, "-d", "--no-show-raw-insn", f"--start-address={lo}",
                          f"--stop-address={hi}", elf], capture_output=True, text=True,
                         check=True).stdout
    caller = None
    for line in out.splitlines():
        m = re.match(r"^[0-9a-f]+ <([^>]+)>:$", line)
        if m:
            caller = m.group(1)
            continue
        m = re.match(r"^\s*[0-9a-f]+:\s+(bl|b|b\.w|b\.n|b[a-z]{2}(?:\.[nw])?)\s+[0-9a-f]+ <([^>+]+)>",
                     line)
        if m and caller is not None and m.group(2) != caller:
            yield caller, m.group(2)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elf", required=True)
    ap.add_argument("--map", required=True)
    ap.add_argument("--entry", default="app_sample_isr")
    ap.add_argument("--objdump", default="arm-none-eabi-objdump")
    args = ap.parse_args()
    with open(args.map) as f:
        lo, hi = memory_region(f.read(), "RAM")
    funcs = functions(args.objdump, args.elf)
    in_ram = {n for n, (a, _) in funcs.items() if lo <= a < hi}
    bad = []
    for name, (addr, sec) in sorted(funcs.items()):
        if sec == ".ramfunc" and name not in in_ram:
            bad.append(f"{name} (.ramfunc) at {addr:#x}, outside RAM")
    if args.entry in funcs and args.entry not in in_ram:
        bad.append(f"the interrupt entry {args.entry} at {funcs[args.entry][0]:#x}, outside RAM")
    checked = 0
    for caller, callee in calls(args.objdump, args.elf, lo, hi):
        v = re.match(r"^__(.+)_veneer$", callee)
        target = v.group(1) if v else callee
        if target not in funcs or caller not in in_ram:
            continue
        checked += 1
        if target in in_ram:
            continue
        if caller == args.entry and target in OFF_PATH:
            continue
        bad.append(f"{target} at {funcs[target][0]:#x} (flash), called by {caller} in SRAM: "
                   "mark its definition GYRO_RAMFUNC (firmware/dsp/ramfunc.h)")
    for b in bad:
        print(f"check_ramfunc: {args.elf}: {b}", file=sys.stderr)
    if not bad:
        print(f"check_ramfunc: {len(in_ram)} functions in SRAM, {checked} calls from SRAM code "
              "checked")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
