#!/usr/bin/env python3
"""gyroctl against a freshly started emulator, as a newcomer runs it: QEMU started, then
gyroctl at once, with no waiting and no retry by the caller.

  1. the first call answers (gyroctl waits for QEMU's port and resends its first line
     until the booting guest answers; before, the first line was lost every time);
  2. a second client, while another one holds QEMU's one connection, is told so;
  3. `log --duration 0.1` records 0.1 s of gyro time with the default --timeout, although
     the emulated gyro runs `stretch` (128) times slower than real time: the wait for each
     record follows the stretch read from `emu` (before, a wall-clock deadline of 5.3 s
     cut the 13 s of wall time this takes).

    test_gyroctl_fresh.py --qemu qemu-system-arm --elf gyro-fw-qemu.elf [--gyroctl PATH]
Exit status 0 pass, 1 fail, 77 skipped (no image)."""

import argparse
import csv
import os
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from fw_qemu import ROOT, SKIP, free_port  # noqa: E402

failures = []


def check(ok, what):
    print(("  ok  " if ok else "  FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def gyroctl(args, url, *cmd, timeout=120):
    t0 = time.monotonic()
    p = subprocess.run([sys.executable, args.gyroctl, "--port", url] + list(cmd),
                       capture_output=True, text=True, timeout=timeout)
    dt = time.monotonic() - t0
    print(f"     $ gyroctl {' '.join(cmd)} -> {p.returncode} in {dt:.1f} s: "
          f"{(p.stdout.strip().splitlines() or [''])[0]} {p.stderr.strip()[-200:]}", flush=True)
    return p, dt


def run(args, url):
    # 1. At once after QEMU started (its port may not even listen yet). --timeout 10
    # leaves room for a loaded machine's boot; the old failure did not depend on it.
    p, dt = gyroctl(args, url, "--timeout", "10", "status")
    check(p.returncode == 0 and "mode " in p.stdout, f"first call to a fresh emulator answers ({dt:.1f} s)")
    # 2. Another client holds QEMU's one connection.
    holder = socket.create_connection(("127.0.0.1", int(url.rsplit(":", 1)[1])))
    try:
        p, _ = gyroctl(args, url, "--timeout", "2", "status")
        check(p.returncode == 3 and "another client" in p.stderr and "Traceback" not in p.stderr,
              "a second client is told that another one holds the port")
    finally:
        holder.close()
    time.sleep(0.5)  # QEMU notices the closed connection and listens again
    # 3. 0.1 s of gyro time at 100 Hz, default options.
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "emu.csv")
        p, dt = gyroctl(args, url, "log", "rate_dps", "drive_amp_v", "--rate", "100",
                        "--duration", "0.1", "--out", out)
        rows = []
        if os.path.isfile(out):
            with open(out) as fh:
                rows = list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
        check(p.returncode == 0 and len(rows) == 10,
              f"log: 10 records of 0.1 s gyro time in {dt:.1f} s of wall time (got {len(rows)})")
        check(bool(rows) and list(rows[0]) == ["t_s", "rate_dps", "drive_amp_v"],
              "the log's header keeps the names asked for")
        check("100%" in p.stderr, "log shows its progress on stderr")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--qemu", default="qemu-system-arm")
    ap.add_argument("--elf", required=True)
    ap.add_argument("--gyroctl", default=os.path.join(ROOT, "tools", "gyroctl"))
    args = ap.parse_args()
    if not os.path.isfile(args.elf):
        print(f"SKIP: {args.elf} not built (cmake --workflow --preset target first)")
        return SKIP
    port = free_port()
    cmd = [args.qemu, "-M", "netduinoplus2", "-nographic", "-monitor", "none",
           "-kernel", args.elf, "-icount", "shift=auto",
           "-serial", f"tcp:127.0.0.1:{port},server=on,wait=on,nodelay=on"]
    qemu = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    try:
        run(args, f"socket://127.0.0.1:{port}")
    except Exception as e:  # noqa: BLE001 - report and fail
        check(False, f"conversation with the emulator: {e}")
    finally:
        qemu.terminate()
        try:
            qemu.wait(timeout=10)
        except subprocess.TimeoutExpired:
            qemu.kill()
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
