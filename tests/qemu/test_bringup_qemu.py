#!/usr/bin/env python3
"""Boot test of gyro-bringup-qemu in QEMU's netduinoplus2 (an STM32F405 model).

Starts qemu-system-arm with the image, talks to the bring-up command line over USART1
(a TCP serial port on 127.0.0.1) and checks:
  * the image boots and answers ("gyro-bringup ready", "clk" reports 168 MHz);
  * the sample interrupt runs at 50 kHz of emulated time: the tick count is compared
    with TIM2, an independent timer model counting emulated microseconds;
  * the ISR measures itself (worst-case cycles within one 3360-cycle period) and the
    tick period it measures is 3360 cycles;
  * a fault is recorded across the reset it causes ("crash", then "fault").

-icount shift=3 (8 ns of emulated time per instruction, about the instruction budget
of the 168 MHz Cortex-M4) makes emulated time a function of the instructions run.
shift=auto is not used: QEMU then raises the shift until the 50 kHz interrupt leaves
the background loop no instructions, and the command line never answers.

Exit codes: 0 pass, 1 fail, 77 skip (image not built: build the target preset first).
"""
import argparse
import os
import re
import socket
import subprocess
import sys
import time

SKIP = 77
RATE_HZ = 50000
CYCLES_PER_TICK = 168000000 // RATE_HZ


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Console:
    def __init__(self, port, deadline):
        import serial  # pyserial

        self.deadline = deadline
        last = None
        while time.monotonic() < deadline:
            try:
                self.port = serial.serial_for_url(f"socket://127.0.0.1:{port}", timeout=0.2)
                break
            except Exception as e:  # QEMU not listening yet
                last = e
                time.sleep(0.1)
        else:
            raise RuntimeError(f"cannot connect to QEMU's serial port: {last}")
        self.buf = b""

    def expect(self, pattern, timeout):
        end = min(time.monotonic() + timeout, self.deadline)
        rx = re.compile(pattern.encode())
        while time.monotonic() < end:
            m = rx.search(self.buf)
            if m:
                line_end = self.buf.find(b"\n", m.end())
                if line_end >= 0:
                    line = self.buf[m.start():line_end].decode(errors="replace").strip()
                    self.buf = self.buf[line_end + 1:]
                    return line
            self.buf += self.port.read(256)
        raise RuntimeError(f"timeout waiting for {pattern!r}; got {self.buf[-300:]!r}")

    def command(self, cmd, reply, timeout=10.0):
        self.port.write(cmd.encode() + b"\r")
        return self.expect(reply, timeout)

    def close(self):
        self.port.close()


def fields(line):
    return {k: int(v, 0) for k, v in re.findall(r"(\w+)=(-?(?:0x[0-9a-f]+|\d+))", line)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--qemu", default="qemu-system-arm")
    ap.add_argument("--elf", required=True)
    ap.add_argument("--timeout", type=float, default=90.0, help="whole test, seconds")
    args = ap.parse_args()

    if not os.path.isfile(args.elf):
        print(f"SKIP: {args.elf} not built (cmake --workflow --preset target first)")
        return SKIP

    port = free_port()
    cmd = [args.qemu, "-M", "netduinoplus2", "-nographic", "-monitor", "none",
           "-kernel", args.elf, "-icount", "shift=3",
           "-serial", f"tcp:127.0.0.1:{port},server=on,wait=on,nodelay=on"]
    deadline = time.monotonic() + args.timeout
    qemu = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    con = None
    try:
        con = Console(port, deadline)
        con.expect(r"gyro-bringup ready", 20.0)
        clk = fields(con.command("clk", r"^clk .*|clk status"))
        check(clk.get("sysclk") == 168000000, f"clock plan reports 168 MHz ({clk})")

        first = fields(con.command("stat", r"stat ticks="))
        t0 = time.monotonic()
        # Let the emulator run long enough for a few thousand ticks.
        while time.monotonic() - t0 < 3.0:
            time.sleep(0.2)
        second = fields(con.command("stat", r"stat ticks="))
        dticks = (second["ticks"] - first["ticks"]) & 0xFFFFFFFF
        dus = (second["uptime_us"] - first["uptime_us"]) & 0xFFFFFFFF
        rate = dticks / (dus * 1e-6) if dus else 0.0
        print(f"     {dticks} ticks in {dus} us of emulated time -> {rate:.1f} Hz "
              f"({dticks / (time.monotonic() - t0):.0f} ticks per wall-clock second)")
        check(dticks >= 1000, f"ticks advance ({dticks} between two stat commands)")
        check(abs(rate / RATE_HZ - 1.0) < 0.02, f"tick rate {rate:.1f} Hz within 2 % of 50 kHz")
        check(0 < second["worst_cyc"] < CYCLES_PER_TICK,
              f"ISR worst case {second['worst_cyc']} cycles < {CYCLES_PER_TICK}")
        check(abs(first["period_min"] - CYCLES_PER_TICK) <= CYCLES_PER_TICK // 20 and
              abs(first["period_max"] - CYCLES_PER_TICK) <= CYCLES_PER_TICK // 20,
              f"tick period {first['period_min']}..{first['period_max']} cycles ~ 3360")
        check(second["overruns"] == 0 and second["uart_drop"] == 0, "no overruns, no lost bytes")

        dac = con.command("dac 100 16000 8192 0", r"dac ok|error")
        check(dac == "dac ok", "dac command accepted")
        adc = fields(con.command("adc", r"adc drive="))
        check(adc == {"drive": (100 - 8192) * 4, "sense": (16000 - 8192) * 4},
              f"ADC loopback sees the DAC frame through the ISR ({adc})")
        check(con.command("dac 1 2 3", r"dac ok|error").startswith("error"),
              "malformed dac command refused")
        check(con.command("dac 100 16000 8192 0 1 2 3 16383", r"dac ok|error") == "dac ok",
              "dac command with the second converter's four codes accepted")
        check(con.command("dac 1 2 3 4 5", r"dac ok|error").startswith("error"),
              "dac command with a partial second converter refused")

        check(con.command("fault clear", r"fault cleared") == "fault cleared", "fault clear")
        check(con.command("fault", r"fault") == "fault none", "no fault recorded")
        con.port.write(b"crash\r")
        con.expect(r"gyro-bringup ready", 20.0)
        rec = fields(con.command("fault", r"^fault .*|fault n="))
        check(rec.get("n") == 1 and rec.get("exc") == 6 and rec.get("cfsr") == 0x00010000,
              f"UsageFault (UNDEFINSTR) recorded across the reset ({rec})")
    except Exception as e:  # noqa: BLE001 - report and fail
        check(False, f"conversation with the image: {e}")
    finally:
        if con is not None:
            con.close()
        qemu.terminate()
        try:
            qemu.wait(timeout=5)
        except subprocess.TimeoutExpired:
            qemu.kill()
            qemu.wait()
    print(f"{1 if failures else 0} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
