#!/usr/bin/env python3
"""Console mode at a real terminal: picocom on the simulator's pty, driven through a
detached tmux session (keys with `tmux send-keys`, the screen with `tmux capture-pane`).

Checks what a person sees: `console on` gives a prompt; typed text is echoed; a line
edited with Backspace (DEL) and Ctrl-H runs as corrected; arrow keys and Ctrl-U/Ctrl-C
give no error; Up brings back the last line. Then gyroctl connects to the port the
person left in console mode and still gets its plain replies, and leaves the port in
machine mode.

Usage: test_console_picocom.py --sim PATH/gyro-sim --scenario PATH/startup.json
       [--gyroctl PATH/tools/gyroctl]
Exit 77 (ctest SKIP_RETURN_CODE) when tmux or picocom is not installed (tools/setup.sh
installs both)."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77


class Screen:
    """picocom in a detached tmux session on its own server socket (-L), so nothing of
    a user's tmux is touched."""

    def __init__(self, port):
        self.sock = f"gyro-console-{os.getpid()}"
        self.tmux = ["tmux", "-L", self.sock]
        env = dict(os.environ, TERM="xterm")
        subprocess.run(self.tmux + ["-f", "/dev/null", "new-session", "-d", "-s", "t", "-x", "132",
                                    "-y", "50", f"picocom --nolock -b 921600 {port}"],
                       check=True, env=env)
        self.env = env

    def keys(self, *keys, literal=False):
        subprocess.run(self.tmux + ["send-keys", "-t", "t"] + (["-l"] if literal else []) + list(keys),
                       check=True, env=self.env)
        time.sleep(0.15)

    def type(self, text):
        self.keys(text, literal=True)

    def text(self):
        r = subprocess.run(self.tmux + ["capture-pane", "-p", "-t", "t", "-S", "-200"],
                           capture_output=True, text=True, env=self.env)
        return r.stdout

    def wait(self, pattern, count=1, timeout_s=10.0):
        t_end = time.monotonic() + timeout_s
        while time.monotonic() < t_end:
            screen = self.text()
            if len(re.findall(pattern, screen, re.M)) >= count:
                return screen
            time.sleep(0.1)
        raise AssertionError(f"not on screen after {timeout_s:g} s: {pattern!r} x{count}\n"
                             f"---- screen ----\n{self.text()}")

    def close(self):
        subprocess.run(self.tmux + ["kill-server"], capture_output=True, env=self.env)


def check(cond, what, screen):
    if not cond:
        raise AssertionError(f"{what}\n---- screen ----\n{screen}")


def run(args, port):
    scr = Screen(port)
    try:
        scr.wait(r"Terminal ready")
        # machine mode by default: nothing is echoed; console on gives the prompt
        scr.type("console on")
        scr.keys("Enter")
        scr.wait(r"^ok console on\s*$")
        scr.wait(r"^gyro>\s*$")
        # echo, and a line edited with Backspace (DEL) and Ctrl-H
        scr.type("get tlm.rate_hx")
        scr.wait(r"^gyro> get tlm\.rate_hx$")
        scr.keys("BSpace")
        scr.type("z")
        scr.keys("Enter")
        scr.wait(r"^gyro> get tlm\.rate_hz\s*$")
        scr.wait(r"^ok tlm\.rate_hz \d+ Hz\s*$")
        scr.type("get sys.fs_hzzz")
        scr.keys("C-h")
        scr.keys("C-h")
        scr.keys("Enter")
        scr.wait(r"^ok sys\.fs_hz 50000 Hz\s*$")
        # arrow keys and other editing keys in a line: consumed without an error
        scr.type("ver")
        scr.keys("Left", "Right", "Down", "Home", "End")
        scr.type("sion")
        scr.keys("Enter")
        scr.wait(r"^ok fw \S+ layout")
        # Ctrl-U and Ctrl-C drop a line: it is not run
        scr.type("drive on")
        scr.keys("C-u")
        scr.type("drive on")
        scr.keys("C-c")
        scr.wait(r"drive on\^C$")
        # Up brings back the last line run (version)
        scr.keys("Up")
        scr.keys("Enter")
        screen = scr.wait(r"^ok fw \S+ layout", count=2)
        check(not re.search(r"^err ", screen, re.M), "an error on the screen", screen)
        check(not re.search(r"^ok drive", screen, re.M), "a dropped line was run", screen)
        check(len(re.findall(r"^gyro>\s*$", screen, re.M)) >= 1, "no prompt at the end", screen)
        print(screen)
    finally:
        scr.close()

    # gyroctl on the port a person left in console mode: its plain reply, and the port
    # back in machine mode afterwards
    if args.gyroctl:
        r = subprocess.run([sys.executable, args.gyroctl, "--port", port, "get", "sys.fs_hz"],
                           capture_output=True, text=True, timeout=60)
        if r.returncode != 0 or r.stdout.strip() != "50000":
            raise AssertionError(f"gyroctl after console mode: rc {r.returncode} "
                                 f"out {r.stdout!r} err {r.stderr!r}")
        import serial  # pyserial (tools/setup.sh)
        with serial.Serial(port, 921600, timeout=0.2) as s:
            s.write(b"console\n")
            got, t_end = b"", time.monotonic() + 5
            while b"\n" not in got and time.monotonic() < t_end:
                got += s.read(64)
        if got != b"ok console off\r\n":
            raise AssertionError(f"after gyroctl, 'console' answered {got!r}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim", required=True)
    ap.add_argument("--scenario", required=True)
    ap.add_argument("--gyroctl")
    args = ap.parse_args()
    missing = [p for p in ("tmux", "picocom") if shutil.which(p) is None]
    if missing:
        print(f"SKIP: {' and '.join(missing)} not installed (tools/setup.sh installs them)")
        return SKIP
    with tempfile.TemporaryDirectory() as d:
        port = os.path.join(d, "gyro.pty")
        sim = subprocess.Popen([args.sim, "--scenario", args.scenario, "--duration", "600", "--quiet",
                                f"--uart-pty={port}"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
        try:
            line = sim.stdout.readline().split()
            if len(line) != 2 or line[0] != "pty":
                print(f"gyro-sim did not start: {line} {sim.stderr.read()}", file=sys.stderr)
                return 1
            run(args, port)
        except AssertionError as e:
            print(f"FAIL: {e}", file=sys.stderr)
            return 1
        finally:
            sim.terminate()
            try:
                sim.wait(timeout=10)
            except subprocess.TimeoutExpired:
                sim.kill()
    print("console at picocom: prompt, echo, editing, arrows, gyroctl afterwards: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
