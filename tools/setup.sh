#!/usr/bin/env bash
# Idempotent set-up for a fresh Debian machine: installs only what is missing.
# Called by tools/run-sim and tools/run-tests before they build; safe to run repeatedly.
set -euo pipefail

APT_PKGS=(
  cmake ninja-build gcc g++ make pkg-config
  libcmocka-dev          # unit tests and HAL mocks
  zlib1g-dev             # reference crc32() for the parameter-store CRC test
  libclang-rt-14-dev     # libFuzzer and sanitizer runtimes for clang (tools/run-fuzz)
  libeigen3-dev          # host-only C++ reference implementations (tests/reference)
  libcjson-dev           # scenario-file parsing in gyro-sim
  cppcheck               # static analysis of firmware/ and hal/
  clang-format           # C style check (ctest clang_format, .clang-format)
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi  # target build
  valgrind               # callgrind instruction counts (benchmarks)
  clang                  # libFuzzer harnesses
  qemu-system-arm        # boots the emulator bring-up image (ctest label qemu)
  tmux picocom           # console mode at a real terminal (ctest e2e_console_picocom)
  python3 python3-pip python3-venv
)
# dask/distributed, pandas, pyarrow, tqdm: tools/lot (the Monte Carlo lot: scheduling,
# the Parquet tables, the progress bar)
PIP_PKGS=(numpy scipy matplotlib allantools pyserial pytest ruff "dask[distributed]" distributed
          pandas pyarrow tqdm)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${APT_PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

PY=${PYTHON:-python3}
need_pip=0
for m in numpy scipy matplotlib allantools serial pytest ruff dask distributed pandas pyarrow tqdm; do
  if ! "$PY" -c "import $m" >/dev/null 2>&1; then need_pip=1; fi
done
if [ "$need_pip" -eq 1 ]; then
  echo "setup: installing Python packages: ${PIP_PKGS[*]}" >&2
  "$PY" -m pip install -q "${PIP_PKGS[@]}" 2>/dev/null \
    || "$PY" -m pip install -q --break-system-packages "${PIP_PKGS[@]}"
fi
