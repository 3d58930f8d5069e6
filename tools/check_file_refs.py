#!/usr/bin/env python3
"""Fail when a comment or a document names a repository file that does not exist.

    check_file_refs.py [--root DIR]

Reads the comments of C/C++ sources, the comments and docstrings of Python, the comments
of CMake and shell files, and the whole text of Markdown pages, and looks for names that
look like files of this repository:

  * a path under a top-level folder of the tree (`firmware/gyro/gyro.c`, `tools/run-sim`,
    `host_sim/scenarios/*.json`): it must exist (a `*` matches as in a shell glob);
  * a relative path or a bare file name with a source or document extension (`gyro.h`,
    `plant/plant.h`, `glossary.md`): some file of the tree must end with it. A relative
    path may also start from the naming file's folder.

Every miss is printed as `path:line: names NAME, which does not exist`; exit 1 if any.
Data files (.csv, .json, .png, ...) named without a top-level folder are outputs of the
tools, not files of the tree, and are not checked; nor is anything after `://` (a URL),
under `build/` or `out/`, `/tmp`, `/dev` or `~`, or written with a placeholder (`<name>`,
`NAME`, `{x}`).
"""

import argparse
import ast
import fnmatch
import io
import os
import re
import sys
import tokenize

# Folders the tools write (`out/report/index.md`), not folders of the tree.
OUTPUT_DIRS = {"out", "build"}
SKIP_DIRS = {"build", ".git", "__pycache__", ".venv", ".ruff_cache", ".pytest_cache"}
C_EXT = (".c", ".h", ".cpp", ".cc", ".hpp")
# Extensions of files the tree holds as sources or documents: a bare name with one of
# these must be a file of the tree.
SOURCE_EXT = ("c", "h", "cpp", "hpp", "py", "md", "ld", "cmake", "sh", "toml", "S", "s")
# Names that look like files but are not files of this tree.
NOT_FILES = {
    "stdio.h", "stdlib.h", "string.h", "math.h", "stdint.h", "stdbool.h", "stddef.h",
    "float.h", "limits.h", "errno.h", "assert.h", "setjmp.h", "stdarg.h", "complex.h",
    "time.h", "signal.h", "unistd.h", "fcntl.h", "poll.h", "termios.h", "getopt.h",
    "ftw.h", "inttypes.h", "cmocka.h", "cJSON.h", "zlib.h", "pty.h", "setup.py",
    "conftest.py", "__init__.py", "__main__.py", "arm_math.h", "core_cm4.h",
    "stm32f4xx.h", "stm32f405xx.h", "sys/stat.h", "sys/types.h", "sys/ioctl.h",
    "sys/select.h", "sys/wait.h", "sys/time.h", "sys/mman.h", "stdatomic.h",
    "libc.so", "pyproject.toml", "ruff.toml",
}


def top_dirs(root):
    return {d for d in os.listdir(root)
            if os.path.isdir(os.path.join(root, d)) and d not in SKIP_DIRS and not d.startswith(".")}


def tree_files(root):
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.startswith(".")]
        for f in filenames:
            out.append(os.path.relpath(os.path.join(dirpath, f), root).replace(os.sep, "/"))
    return out


# --------------------------------------------------------------- text to check ---

def c_comments(text):
    """(line, text) of each comment of C/C++ source."""
    out = []
    for m in re.finditer(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', text, re.S):
        if m.group(0)[0] == "/":
            out.append((text.count("\n", 0, m.start()) + 1, m.group(0)))
    return out


def hash_comments(text):
    """(line, text) of each # comment of a CMake or shell file (a #! line included)."""
    out = []
    for i, line in enumerate(text.split("\n"), 1):
        m = re.search(r"(?:^|\s)#.*$", line)
        if m:
            out.append((i, m.group(0)))
    return out


def py_comments(text, path):
    """(line, text) of each comment and docstring of Python source."""
    out = []
    try:
        for tok in tokenize.generate_tokens(io.StringIO(text).readline):
            if tok.type == tokenize.COMMENT:
                out.append((tok.start[0], tok.string))
        tree = ast.parse(text, filename=path)
    except (SyntaxError, tokenize.TokenError):
        return hash_comments(text)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                out.append((body[0].lineno, body[0].value.value))
    return out


def file_kind(path, name):
    if name.endswith(C_EXT):
        return "c"
    if name.endswith(".py"):
        return "py"
    if name.endswith(".md"):
        return "md"
    if name == "CMakeLists.txt" or name.endswith((".cmake", ".sh", ".ld", ".toml")):
        return "hash" if not name.endswith(".ld") else "c"
    if "." not in name:
        try:
            with open(path, "rb") as fh:
                first = fh.readline(200)
        except OSError:
            return None
        if first.startswith(b"#!"):
            return "py" if b"python" in first else "hash"
    return None


def pieces(path, kind):
    with open(path, encoding="utf-8", errors="replace") as fh:
        text = fh.read()
    if kind == "c":
        return c_comments(text)
    if kind == "py":
        return py_comments(text, path)
    if kind == "hash":
        return hash_comments(text)
    return [(1, text)]


# ------------------------------------------------------------------- matching ---

def _candidates(text, tops):
    """(offset, name) of each file-like name in text."""
    alts = [r"(?:[\w+-]+/)*[\w+-]+\.(?:" + "|".join(SOURCE_EXT) + r")"]  # source-like name
    if tops:  # under a top folder
        top_alt = "|".join(sorted((re.escape(t) for t in tops), key=len, reverse=True))
        alts.insert(0, r"(?:" + top_alt + r")/[\w.*/+-]*[\w*]")
    pat = re.compile(r"(?<![\w./~<>{}$*-])(" + "|".join(alts) + r")(?![\w/<>{}-])")
    for m in pat.finditer(text):
        yield m.start(), m.group(1)


def exists(name, here, root, files, tops):
    """Whether name is a file or folder of the tree: from the root or from the naming
    file's folder `here`; a path without its extension (a module `host_sim/plant/mech`, a
    program `tests/e2e/fw_pty_host`) counts when a file of that stem exists."""
    first = name.split("/", 1)[0]
    if first in OUTPUT_DIRS or any(re.fullmatch(r"[A-Z][A-Z0-9_]*", c) for c in re.split(r"[/.]", name)):
        return True
    if "/" in name:
        for base in ("", here):
            p = os.path.normpath(os.path.join(base, name)).replace(os.sep, "/")
            if any(c in p for c in "*?["):
                if any(fnmatch.fnmatchcase(f, p) or fnmatch.fnmatchcase(f, p + "/*") for f in files):
                    return True
            elif os.path.exists(os.path.join(root, p)) or any(f.startswith(p + ".") for f in files):
                return True
        if first in tops:
            return False
    if name in NOT_FILES or name.split("/")[-1] in NOT_FILES:
        return True
    suffix = "/" + name
    return any(f == name or f.endswith(suffix) for f in files)


def check(root):
    tops = top_dirs(root)
    files = tree_files(root)
    misses = []
    for rel in sorted(files):
        path = os.path.join(root, rel)
        kind = file_kind(path, os.path.basename(rel))
        if kind is None:
            continue
        for line0, text in pieces(path, kind):
            for off, name in _candidates(text, tops):
                name = name.rstrip(".")
                if text[max(0, off - 3):off].endswith("://"):
                    continue
                if not exists(name, os.path.dirname(rel), root, files, tops):
                    line = line0 + text.count("\n", 0, off)
                    misses.append((rel, line, name))
    return misses


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    args = ap.parse_args(argv)
    misses = check(args.root)
    for rel, line, name in misses:
        print(f"{rel}:{line}: names {name}, which does not exist")
    if misses:
        print(f"check_file_refs: {len(misses)} reference(s) to files that do not exist",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
