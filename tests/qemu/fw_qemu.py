"""Run a firmware image in QEMU's netduinoplus2 and talk to its command line over the
TCP serial port, with gyroctl's link (tools/gyroctl_lib/link.py). Shared by the gyro-fw-qemu
tests in this directory.

    with Emulator(qemu, elf) as emu:      # boots; emu.link is a gyroctl Link
        st = emu.status()                 # {"mode": "LOCKED", "ticks": "123", ...}

QEMU runs with -icount shift=auto (emulated time follows real time, no tick lost to
the host's pace; a fixed shift is possible for instruction counts) and
-serial tcp:127.0.0.1:PORT,server=on,wait=on,nodelay=on (without nodelay every byte
takes ~44 ms; with wait=on the guest starts when the link connects).
"""

import os
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tools"))

from gyroctl_lib.link import Link, LinkError  # noqa: E402

SKIP = 77


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def kv(lines):
    """'- key value' data lines (prefix already removed by the link) -> dict of strings."""
    out = {}
    for ln in lines:
        k, _, v = ln.partition(" ")
        out[k] = v
    return out


class Emulator:
    def __init__(self, qemu, elf, icount="auto", boot_timeout_s=60.0):
        self.port = free_port()
        self.url = f"socket://127.0.0.1:{self.port}"
        self.cmd = [qemu, "-M", "netduinoplus2", "-nographic", "-monitor", "none",
                    "-kernel", elf, "-icount", f"shift={icount}",
                    "-serial", f"tcp:127.0.0.1:{self.port},server=on,wait=on,nodelay=on"]
        self.proc = subprocess.Popen(self.cmd, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self.link = None
        t_end = time.monotonic() + 10.0
        last = None
        while time.monotonic() < t_end:
            try:
                self.link = Link(self.url, timeout_s=10.0)
                break
            except LinkError as e:  # QEMU not listening yet
                last = e
                time.sleep(0.1)
        if self.link is None:
            self.close()
            raise RuntimeError(f"cannot connect to QEMU's serial port: {last}")
        self.boot_s = self._wait_boot(boot_timeout_s)

    def _wait_boot(self, timeout_s):
        """The command line answers once main has started the sample clock."""
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout_s:
            if self.proc.poll() is not None:
                raise RuntimeError(f"QEMU exited ({self.proc.returncode}): "
                                   f"{self.proc.stdout.read().decode(errors='replace')}")
            try:
                self.link.command("version", timeout_s=1.0)
                return time.monotonic() - t0
            except LinkError:
                pass
        raise RuntimeError(f"the image did not answer within {timeout_s} s")

    def command(self, line, timeout_s=10.0):
        return self.link.command(line, timeout_s=timeout_s)

    def status(self):
        r = self.command("status")
        if not r.ok:
            raise RuntimeError(f"status: {r.final}")
        return kv(r.data)

    def emu(self):
        r = self.command("emu")
        if not r.ok:
            raise RuntimeError(f"emu: {r.final}")
        return kv(r.data)

    def wait_ticks(self, n, timeout_s=60.0):
        """Wait until the sample clock has run n more ticks (plant time n / 50 kHz)."""
        t0 = int(self.status()["ticks"])
        t_end = time.monotonic() + timeout_s
        while time.monotonic() < t_end:
            time.sleep(0.2)
            t = int(self.status()["ticks"])
            if (t - t0) & 0xFFFFFFFF >= n:
                return t
        raise RuntimeError(f"{n} ticks did not run within {timeout_s} s")

    def close(self):
        if self.link is not None:
            self.link.close()
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
