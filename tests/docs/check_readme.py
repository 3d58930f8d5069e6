#!/usr/bin/env python3
"""Run the README's shell command blocks, so the README cannot drift from the code.

Every fenced block whose language is sh, bash or shell must be preceded (blank lines
allowed) by one mark, an HTML comment that a rendered README does not show:

    <!-- readme-test: run -->                    run the block as written
    <!-- readme-test: run-short: COMMANDS        run COMMANDS instead (a shortened form of
         why: REASON -->                         the block; may span several lines), and
                                                 REASON says what was shortened
                                                 COMMANDS may instead be lines
                                                 `replace: OLD => NEW`: the block as
                                                 written with each OLD (which must
                                                 occur) replaced, so the block stays the
                                                 one source of the commands
    <!-- readme-test: skip: REASON -->           not run, and the reason says why
                                                 (hardware, minutes of CPU, QEMU ...)

A block without a mark fails the check and is named by its line, so a new block gets a
mark when it is written. Blocks run in order from the repository root with
`bash -euo pipefail`; what a block starts in the background is stopped when it ends.
The fixed pty path of the tuning example (/tmp/gyro.pty) is replaced by a private one,
so two runs on one machine do not share a simulator.

After the run, `git status` must show nothing new: a command in the README must not
write into the tracked tree (outputs go under out/ or build/, which .gitignore lists).

    check_readme.py [--readme README.md] [--root DIR] [--list] [--only LINE]
Exit status: 0 every block ran (or was skipped with a reason), 1 a block failed, lacks
a mark or wrote into the tree, 2 usage or unreadable README.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

FENCE = re.compile(r"^```\s*([A-Za-z0-9_+-]*)\s*$")
SHELL_LANGS = {"sh", "bash", "shell"}
MARK = re.compile(r"<!--\s*readme-test:\s*(run-short|run|skip)\s*(?::\s*(.*?))?\s*-->", re.S)
BLOCK_TIMEOUT_S = 300


@dataclasses.dataclass
class Block:
    line: int          # 1-based line of the opening fence
    text: str          # the commands as written
    kind: str | None   # run, run-short, skip, or None (no mark)
    arg: str = ""      # replacement commands (run-short) or reason (skip)
    why: str = ""      # why a run-short block is shortened


def _mark_before(lines, fence_idx):
    """The mark in the text just above the fence (only blank lines between)."""
    j = fence_idx - 1
    while j >= 0 and not lines[j].strip():
        j -= 1
    if j < 0 or not lines[j].rstrip().endswith("-->"):
        return None, ""
    # Collect the comment, which may span lines, back to its opening "<!--".
    k = j
    while k >= 0 and "<!--" not in lines[k]:
        k -= 1
    if k < 0:
        return None, ""
    m = MARK.search("\n".join(lines[k:j + 1]))
    if not m:
        return None, ""
    return m.group(1), (m.group(2) or "").strip()


def parse(text: str) -> list:
    lines = text.splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m or not m.group(1):
            i += 1 if not m else _skip_fence(lines, i)
            continue
        end = i + 1
        while end < len(lines) and not lines[end].startswith("```"):
            end += 1
        if m.group(1) in SHELL_LANGS:
            kind, arg = _mark_before(lines, i)
            why = ""
            if kind == "run-short":
                parts = re.split(r"^\s*why:\s*", arg, maxsplit=1, flags=re.M)
                arg, why = parts[0].strip(), (parts[1].strip() if len(parts) > 1 else "")
            blocks.append(Block(i + 1, "\n".join(lines[i + 1:end]), kind, arg, why))
        i = end + 1
    return blocks


def _skip_fence(lines, i):
    """Length of an unlabelled fenced block (output listings), fences included."""
    end = i + 1
    while end < len(lines) and not lines[end].startswith("```"):
        end += 1
    return end - i + 1


def problems(blocks) -> list:
    out = []
    for b in blocks:
        first = b.text.strip().splitlines()[0] if b.text.strip() else "(empty)"
        if b.kind is None:
            out.append(f"README.md:{b.line}: shell block has no readme-test mark "
                       f"(run, run-short: COMMANDS or skip: REASON): {first}")
        elif b.kind == "skip" and not b.arg:
            out.append(f"README.md:{b.line}: skip without a reason: {first}")
        elif b.kind == "run-short" and not (b.arg and b.why):
            out.append(f"README.md:{b.line}: run-short needs COMMANDS and 'why: REASON': {first}")
    return out


def tree_state(root):
    """Modified and untracked, not ignored paths (None outside a git work tree)."""
    try:
        r = subprocess.run(["git", "-C", root, "status", "--porcelain", "--untracked-files=all"],
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if r.returncode != 0:
        return None
    return set(r.stdout.splitlines())


REPLACE = re.compile(r"^\s*replace:\s*(.*?)\s*=>\s?(.*)$")


def script_of(b: Block) -> str:
    """The commands to run: the block, its replacement, or the block with the
    `replace:` substitutions applied (ValueError when an OLD no longer occurs)."""
    if b.kind != "run-short":
        return b.text
    lines = [ln for ln in b.arg.splitlines() if ln.strip()]
    subs = [REPLACE.match(ln) for ln in lines]
    if not lines or not all(subs):
        return b.arg
    text = b.text
    for m in subs:
        old, new = m.group(1), m.group(2).rstrip()
        if old not in text:
            raise ValueError(f"replace: '{old}' is not in the block any more")
        text = text.replace(old, new)
    return text


def stop_group(p: subprocess.Popen) -> None:
    """SIGTERM to the block's process group, SIGKILL to what is left after 2 s."""
    for sig, grace in ((signal.SIGTERM, 2.0), (signal.SIGKILL, 0.0)):
        try:
            os.killpg(p.pid, sig)
        except ProcessLookupError:
            return
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline:
            try:
                os.killpg(p.pid, 0)
            except ProcessLookupError:
                return
            time.sleep(0.05)
    try:
        p.wait(timeout=5)
    except subprocess.TimeoutExpired:
        pass


def run_block(b: Block, root: str, pty: str) -> bool:
    try:
        script = script_of(b)
    except ValueError as e:
        print(f"--- README.md:{b.line}: {e}", flush=True)
        return False
    script = script.replace("/tmp/gyro.pty", pty)
    # Background jobs of the block (a simulator on a pty) end with it.
    wrapped = "trap 'kill $(jobs -p) 2>/dev/null || true; wait 2>/dev/null || true' EXIT\n" + script
    print(f"--- README.md:{b.line} ({b.kind})\n{script}", flush=True)
    t0 = time.monotonic()
    # Its own process group: whatever the block leaves running (a job the trap did not
    # see, a process of a subshell) is stopped with the group, and cannot hold the
    # caller's output open after the block ended.
    p = subprocess.Popen(["bash", "-euo", "pipefail", "-c", wrapped], cwd=root,
                         stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        rc = p.wait(timeout=BLOCK_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        rc = "timeout"
    stop_group(p)
    dt = time.monotonic() - t0
    print(f"--- README.md:{b.line}: exit {rc} after {dt:.1f} s", flush=True)
    return rc == 0


def main(argv=None) -> int:
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description="Run the README's shell blocks.")
    ap.add_argument("--root", default=os.path.normpath(os.path.join(here, "..", "..")))
    ap.add_argument("--readme", default=None, help="default: ROOT/README.md")
    ap.add_argument("--list", action="store_true", help="list the blocks and their marks, run nothing")
    ap.add_argument("--only", type=int, action="append", help="run only the block at this line")
    a = ap.parse_args(argv)
    path = a.readme or os.path.join(a.root, "README.md")
    try:
        with open(path, encoding="utf-8") as fh:
            blocks = parse(fh.read())
    except OSError as e:
        print(f"check_readme: {path}: {e.strerror}", file=sys.stderr)
        return 2
    bad = problems(blocks)
    if a.list:
        for b in blocks:
            print(f"{b.line:5d} {b.kind or 'UNMARKED':9s} {(b.why or b.arg)[:70]!r}")
        return 1 if bad else 0
    if bad:
        print("\n".join(bad), file=sys.stderr)
        return 1
    before = tree_state(a.root)
    failed = []
    with tempfile.TemporaryDirectory(prefix="readme-") as tmp:
        pty = os.path.join(tmp, "gyro.pty")
        for b in blocks:
            if a.only and b.line not in a.only:
                continue
            if b.kind == "skip":
                print(f"--- README.md:{b.line}: skipped: {b.arg}")
                continue
            if not run_block(b, a.root, pty):
                failed.append(f"README.md:{b.line}: block failed")
    after = tree_state(a.root)
    if before is not None and after is not None:
        for entry in sorted(after - before):
            failed.append(f"the README's commands wrote into the tracked tree: {entry}")
    for f in failed:
        print(f, file=sys.stderr)
    print(f"check_readme: {len(blocks)} blocks, {len(failed)} problems")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
