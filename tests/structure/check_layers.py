#!/usr/bin/env python3
"""Standing checks of the source tree's layering and of each hardware fact written once.

  constants  no pi literal, no M_PI (nor 2 pi, 180/pi, pi/180 written out) in the C/C++
             sources of firmware/, hal/, host_sim/ and tools/ outside the two constants
             headers: firmware/dsp/math_const.h (the firmware's, float and double) and
             host_sim/plant/plant_const.h (the plant's, double).
  board      firmware/ names no board: no STM32 (any case, so no stm32f4_* header and no
             STM32F4_QEMU-style macro), no emulator or board name, no include of a header
             that lives in a board or port folder of hal/, no #if on a BOARD_ macro, in code
             and comments alike. The firmware sees hal/include and the build-selected
             "board.h" only.

Usage: check_layers.py ROOT {constants,board,selftest}
"""
import os
import re
import sys

SOURCE_EXT = (".c", ".h", ".cpp", ".hpp", ".cc")
CONST_DIRS = ("firmware", "hal", "host_sim", "tools")
CONST_HEADERS = {"firmware/dsp/math_const.h", "host_sim/plant/plant_const.h"}
# pi, 2 pi, 180/pi, pi/180 written as a decimal literal (six significant digits or more),
# and the C library's M_PI family.
CONST_RE = re.compile(r"3\.14159|6\.28318|57\.2957|0\.0174532|\bM_PI\w*\b|\bM_1_PI\b|\bM_2_PI\b")

BOARD_WORDS_RE = re.compile(r"stm32|netduino|qemu|f405", re.IGNORECASE)
BOARD_IF_RE = re.compile(r"^\s*#\s*(if|ifdef|ifndef|elif)\b.*\bBOARD_\w*", re.MULTILINE)
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.MULTILINE)


def sources(root, top):
    for d, dirs, files in os.walk(os.path.join(root, top)):
        dirs[:] = sorted(x for x in dirs if not x.startswith(".") and x != "build")
        for f in sorted(files):
            if f.endswith(SOURCE_EXT):
                p = os.path.join(d, f)
                yield os.path.relpath(p, root).replace(os.sep, "/"), p


def constant_findings(rel, text):
    if rel in CONST_HEADERS:
        return []
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        m = CONST_RE.search(line)
        if m:
            out.append(f"{rel}:{n}: '{m.group(0)}' outside the constants headers: {line.strip()}")
    return out


def port_headers(root):
    """Basenames of headers in hal/ outside the generic interface (hal/include)."""
    names = set()
    for rel, _ in sources(root, "hal"):
        if rel.endswith(".h") and not rel.startswith("hal/include/"):
            names.add(os.path.basename(rel))
    names.discard("board.h")  # the build selects which board's; the name is generic
    return names


def board_findings(rel, text, port):
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        m = BOARD_WORDS_RE.search(line)
        if m:
            out.append(f"{rel}:{n}: names a board or port ('{m.group(0)}'): {line.strip()}")
    for m in BOARD_IF_RE.finditer(text):
        n = text.count("\n", 0, m.start()) + 1
        out.append(f"{rel}:{n}: conditional on a board macro: {m.group(0).strip()}")
    for m in INCLUDE_RE.finditer(text):
        if os.path.basename(m.group(1)) in port:
            n = text.count("\n", 0, m.start()) + 1
            out.append(f"{rel}:{n}: includes a board/port header \"{m.group(1)}\"")
    return out


def check(root, what):
    findings = []
    if what == "constants":
        for top in CONST_DIRS:
            for rel, p in sources(root, top):
                with open(p, encoding="utf-8", errors="replace") as fh:
                    findings += constant_findings(rel, fh.read())
    else:
        port = port_headers(root)
        for rel, p in sources(root, "firmware"):
            with open(p, encoding="utf-8", errors="replace") as fh:
                findings += board_findings(rel, fh.read(), port)
        cm = os.path.join(root, "firmware", "CMakeLists.txt")
        with open(cm, encoding="utf-8") as fh:
            findings += board_findings("firmware/CMakeLists.txt", fh.read(), port)
    return findings


def selftest():
    """The checks catch what they are for (and pass what they must pass)."""
    bad_c = [("firmware/gyro/x.c", "double w = 2.0 * 3.14159265358979 * f;"),
             ("host_sim/plant/x.c", "x = M_PI / 2;"),
             ("tools/x/y.c", "d = r * 57.29577951308232;"),
             ("hal/x.c", "w = 6.283185307179586 * f;")]
    for rel, text in bad_c:
        assert constant_findings(rel, text), rel
    assert not constant_findings("firmware/dsp/math_const.h", "#define FM_PI 3.14159265358979323846")
    assert not constant_findings("firmware/gyro/x.c", "w = 2.0 * FM_PI * f; /* 2 pi f */")
    port = {"stm32f4_core.h", "stm32f4_stack.h"}
    bad_b = ['#include "stm32f4_core.h"', '#include "hal/../boards/x/stm32f4_stack.h"',
             "/* on the STM32F4 a sector erase stalls */", "#ifdef STM32F4_QEMU",
             "#if BOARD_HAS_CCM", "#ifdef BOARD_REF", "/* in QEMU */"]
    for text in bad_b:
        assert board_findings("firmware/x.c", text, port), text
    for text in ['#include "board.h"', '#include "hal/hal_adc.h"', "x = BOARD_SAMPLE_RATE_HZ;",
                 "/* one VSQRT.F32 on the Cortex-M4F */"]:
        assert not board_findings("firmware/x.c", text, port), text
    print("selftest: ok")
    return 0


def main(argv):
    if len(argv) != 3 or argv[2] not in ("constants", "board", "selftest"):
        print(__doc__, file=sys.stderr)
        return 2
    if argv[2] == "selftest":
        return selftest()
    findings = check(argv[1], argv[2])
    for f in findings:
        print(f)
    print(f"{argv[2]}: {len(findings)} finding(s)")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
