#!/usr/bin/env python3
"""Fail when the #include graph of firmware/ and hal/ has a cycle.

Two graphs are checked:
  * files: a module is a .c/.h pair (NAME.c and NAME.h are one node, so the usual
    "NAME.c includes NAME.h" is no edge); module A depends on module B when A's .c or .h
    includes B's header. A cycle means neither module can be understood, tested or
    replaced without the other.
  * folders: firmware/app, firmware/comm, hal/host, ... ; folder X depends on folder Y when
    a file in X includes a file in Y. A cycle means the layers do not say which is lower.

Only quoted includes that resolve to a file of the tree count (system headers do not).
Exit status 0 when both graphs are acyclic, 1 with every cycle found printed otherwise.
"""
import argparse
import os
import re
import sys

INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def source_files(root, tops):
    for top in tops:
        base = os.path.join(root, top)
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames.sort()
            for name in sorted(filenames):
                if name.endswith((".c", ".h")):
                    yield os.path.relpath(os.path.join(dirpath, name), root)


def resolve(root, including, target, search_dirs, all_files):
    """The repository path an include names, or None when it is outside the tree.

    Tried in the compiler's order: beside the including file, then the include roots
    every target gets; last, a file of the tree that is the only one ending in the
    included path (board and emulator folders reach each other through -I options).
    """
    candidates = [os.path.join(os.path.dirname(including), target)]
    candidates += [os.path.join(d, target) for d in search_dirs]
    for cand in candidates:
        path = os.path.normpath(cand)
        if os.path.isfile(os.path.join(root, path)):
            return path
    tail = "/" + os.path.normpath(target)
    hits = [f for f in all_files if ("/" + f).endswith(tail)]
    return hits[0] if len(hits) == 1 else None


def module_of(path):
    return os.path.splitext(path)[0]


def build_graphs(root, tops, search_dirs):
    files = list(source_files(root, tops))
    mod_edges = {}
    dir_edges = {}
    for path in files:
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        src_mod = module_of(path)
        src_dir = os.path.dirname(path)
        mod_edges.setdefault(src_mod, set())
        dir_edges.setdefault(src_dir, set())
        for target in INCLUDE_RE.findall(text):
            dst = resolve(root, path, target, search_dirs, files)
            if dst is None:
                continue
            dst_mod = module_of(dst)
            if dst_mod != src_mod:
                mod_edges[src_mod].add(dst_mod)
            dst_dir = os.path.dirname(dst)
            if dst_dir != src_dir:
                dir_edges[src_dir].add(dst_dir)
    return mod_edges, dir_edges


def cycles(edges):
    """Every strongly connected component with more than one node (Tarjan)."""
    index = {}
    low = {}
    on_stack = set()
    stack = []
    found = []
    counter = [0]

    def visit(v):
        # Iterative to stay clear of Python's recursion limit on a deep tree.
        work = [(v, iter(sorted(edges.get(v, ()))))]
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        while work:
            node, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                    advanced = True
                    break
                if w in on_stack:
                    low[node] = min(low[node], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    found.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def describe(comp, edges):
    members = set(comp)
    lines = []
    for v in comp:
        inside = sorted(w for w in edges.get(v, ()) if w in members)
        lines.append(f"    {v} -> {', '.join(inside)}")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(__file__), "..", ".."))
    args = ap.parse_args(argv)
    root = os.path.abspath(args.root)
    tops = ["firmware", "hal"]
    # The include roots the build gives every target (firmware/CMakeLists.txt, hal/).
    search_dirs = ["firmware", "hal/include", "hal"]
    mod_edges, dir_edges = build_graphs(root, tops, search_dirs)
    bad = 0
    for comp in cycles(dir_edges):
        print("folder cycle:\n" + describe(comp, dir_edges))
        bad += 1
    for comp in cycles(mod_edges):
        print("file cycle:\n" + describe(comp, mod_edges))
        bad += 1
    if bad:
        print(f"{bad} include cycle(s) in {', '.join(tops)}")
        return 1
    print(f"no include cycle: {len(mod_edges)} modules, {len(dir_edges)} folders")
    return 0


if __name__ == "__main__":
    sys.exit(main())
