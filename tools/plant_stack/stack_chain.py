"""Deepest static call chain through gcc -fcallgraph-info=su files (*.ci in the current
directory): sum of the frames along the worst path from each root. Recursion is cut."""
import glob
import re
import sys


def main():
    root_dir, roots = sys.argv[1], sys.argv[2:]
    frames, edges = {}, {}
    for path in glob.glob("*.ci"):
        text = open(path, encoding="utf-8").read().replace(root_dir + "/host_sim/plant/", "")
        for m in re.finditer(r'node: \{ title: "([^"]+)" label: "([^"]*)"', text):
            size = re.search(r"\\n(\d+) bytes", m.group(2))
            frames[m.group(1)] = int(size.group(1)) if size else frames.get(m.group(1), 0)
        for m in re.finditer(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"', text):
            edges.setdefault(m.group(1), set()).add(m.group(2))

    def worst(node, seen):
        if node in seen:
            return 0, []
        best = (0, [])
        for callee in edges.get(node, ()):
            cand = worst(callee, seen | {node})
            if cand[0] > best[0]:
                best = cand
        return frames.get(node, 0) + best[0], [f"{node} {frames.get(node, 0)}"] + best[1]

    for r in roots:
        total, chain = worst(r, frozenset())
        print(f"{r}: {total} bytes: " + " -> ".join(chain))


if __name__ == "__main__":
    main()
