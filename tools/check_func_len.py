#!/usr/bin/env python3
"""Fail when a function is longer than the limit (150 lines), in C and in Python.

    check_func_len.py [--root DIR] [--max N] [DIR ...]

Directories default to firmware/ hal/ host_sim/ tools/. A function's length counts every
line from its name to its closing brace (C) or its last statement (Python), comments and
blank lines included: what a reader has to hold at once. Every violation is printed as
`path:line: name is N lines (limit M)`, so one run lists them all; exit 1 if there are any.

C is read by brace matching on the text with comments, strings, character constants and
preprocessor lines blanked: a top-level `{` whose previous token is `)` opens a function
body (an initialiser's `= {` or a `struct x {` does not). Python is read with `ast`: the
source files are *.py and the extension-less scripts whose first line names python.
"""

import argparse
import ast
import os
import re
import sys

DEFAULT_DIRS = ("firmware", "hal", "host_sim", "tools")
C_EXT = (".c", ".h", ".cpp", ".cc", ".hpp")
SKIP_DIRS = {"build", ".git", "__pycache__", ".venv", ".ruff_cache"}

_C_TOKENS = re.compile(
    r"//[^\n]*"                 # line comment
    r"|/\*.*?\*/"               # block comment
    r'|"(?:\\.|[^"\\\n])*"'     # string literal
    r"|'(?:\\.|[^'\\\n])*'",    # character constant
    re.S,
)


def _blank(m):
    """Keep the newlines (line numbers) of a comment or literal, blank the rest."""
    return re.sub(r"[^\n]", " ", m.group(0))


def strip_c(text):
    """The C text with comments, literals and preprocessor lines (with continuations) blanked."""
    text = _C_TOKENS.sub(_blank, text)
    out = []
    cont = False
    for line in text.split("\n"):
        if cont or line.lstrip().startswith("#"):
            cont = line.rstrip().endswith("\\")
            out.append("")
        else:
            out.append(line)
    return "\n".join(out)


def c_functions(text):
    """(name, first line, line count) of each function definition in C source text."""
    s = strip_c(text)
    funcs = []
    open_func = None  # (name, first line) of the body being read
    depth = 0
    for i, ch in enumerate(s):
        if ch == "{":
            if depth == 0:
                j = i - 1
                while j >= 0 and s[j].isspace():
                    j -= 1
                if j >= 0 and s[j] == ")":
                    name, name_pos = _c_name_before(s, j)
                    if name:
                        open_func = (name, s.count("\n", 0, name_pos) + 1)
            depth += 1
        elif ch == "}":
            depth = max(depth - 1, 0)
            if depth == 0 and open_func:
                name, first = open_func
                funcs.append((name, first, s.count("\n", 0, i) + 1 - first + 1))
                open_func = None
    return funcs


def _c_name_before(s, close):
    """The identifier in front of the parameter list that ends at s[close] == ')'.

    Steps over trailing parenthesised groups such as __attribute__((...)) back to the
    parameter list whose opener follows an identifier that is not a keyword or attribute.
    """
    j = close
    while j >= 0:
        depth = 0
        k = j
        while k >= 0:
            if s[k] == ")":
                depth += 1
            elif s[k] == "(":
                depth -= 1
                if depth == 0:
                    break
            k -= 1
        if k < 0:
            return None, 0
        m = re.search(r"([A-Za-z_]\w*)\s*$", s[:k])
        if not m:
            return None, 0
        name = m.group(1)
        if name in ("__attribute__", "__declspec", "alignas", "_Alignas"):
            # attribute after the parameter list: keep looking left of it
            j = m.start(1) - 1
            while j >= 0 and s[j].isspace():
                j -= 1
            if j < 0 or s[j] != ")":
                return None, 0
            continue
        if name in ("if", "for", "while", "switch", "return", "sizeof"):
            return None, 0
        return name, m.start(1)
    return None, 0


def py_functions(text, path):
    """(name, first line, line count) of each function and method in Python source text."""
    try:
        tree = ast.parse(text, filename=path)
    except SyntaxError as e:
        raise SystemExit(f"{path}:{e.lineno}: cannot parse: {e.msg}") from None
    out = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno] + [d.lineno for d in node.decorator_list])
            out.append((node.name, first, node.end_lineno - first + 1))
    return out


def is_python_script(path):
    try:
        with open(path, "rb") as fh:
            first = fh.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and b"python" in first


def source_files(root, dirs):
    for d in dirs:
        base = os.path.join(root, d)
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(x for x in dirnames if x not in SKIP_DIRS)
            for f in sorted(filenames):
                p = os.path.join(dirpath, f)
                if f.endswith(C_EXT):
                    yield p, "c"
                elif f.endswith(".py") or ("." not in f and is_python_script(p)):
                    yield p, "py"


def violations(root, dirs, limit):
    found = []
    for path, kind in source_files(root, dirs):
        with open(path, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        funcs = c_functions(text) if kind == "c" else py_functions(text, path)
        rel = os.path.relpath(path, root)
        for name, line, count in funcs:
            if count > limit:
                found.append((rel, line, name, count))
    return found


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--max", type=int, default=150, help="longest allowed function, lines")
    ap.add_argument("dirs", nargs="*", default=list(DEFAULT_DIRS))
    args = ap.parse_args(argv)
    found = violations(args.root, args.dirs, args.max)
    for rel, line, name, count in found:
        print(f"{rel}:{line}: {name} is {count} lines (limit {args.max})")
    if found:
        print(f"check_func_len: {len(found)} function(s) longer than {args.max} lines",
              file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
