#!/usr/bin/env python3
"""Check (or apply) the C/C++ layout of .clang-format over the source folders.

    check_format.py [--root DIR] [--fix] [DIR ...]

Directories default to firmware/ hal/ host_sim/ tests/ tools/. Without --fix, runs
`clang-format --dry-run --Werror` over every .c/.h/.cpp/.hpp file and prints each file
that differs (with clang-format's own report); exit 1 if any does. With --fix, rewrites
them in place. Exit 77 (ctest: skipped) when clang-format is not installed
(tools/setup.sh installs it); $CLANG_FORMAT names another binary.
"""

import argparse
import os
import shutil
import subprocess
import sys

DEFAULT_DIRS = ("firmware", "hal", "host_sim", "tests", "tools")
C_EXT = (".c", ".h", ".cpp", ".hpp", ".cc")
SKIP_DIRS = {"build", ".git", "__pycache__"}


def sources(root, dirs):
    for d in dirs:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, d)):
            dirnames[:] = sorted(x for x in dirnames if x not in SKIP_DIRS)
            for f in sorted(filenames):
                if f.endswith(C_EXT):
                    yield os.path.relpath(os.path.join(dirpath, f), root)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--fix", action="store_true", help="reformat the files in place")
    ap.add_argument("dirs", nargs="*", default=list(DEFAULT_DIRS))
    a = ap.parse_args(argv)
    exe = os.environ.get("CLANG_FORMAT") or shutil.which("clang-format")
    if not exe:
        print("check_format: clang-format not found (tools/setup.sh installs it): skipped",
              file=sys.stderr)
        return 77
    files = list(sources(a.root, a.dirs))
    if a.fix:
        subprocess.run([exe, "-i", "--style=file", *files], cwd=a.root, check=True)
        print(f"check_format: formatted {len(files)} files")
        return 0
    bad = []
    for f in files:
        r = subprocess.run([exe, "--dry-run", "--Werror", "--style=file", f], cwd=a.root,
                           capture_output=True, text=True)
        if r.returncode != 0:
            bad.append(f)
            print(f"{f}: not formatted as .clang-format says")
    if bad:
        print(f"check_format: {len(bad)} of {len(files)} files differ from .clang-format: "
              f"python3 tools/check_format.py --fix {' '.join(a.dirs)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
