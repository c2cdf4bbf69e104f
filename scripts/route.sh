#!/usr/bin/env bash
# Routed timing of the blocks that are meant to close it on their own (issue 22's path
# steppers for 4 axes, which hold its path sequencer, interpolator and step/dir generators;
# the motion core, issue 23): Yosys
# synth_ecp5, then nextpnr-ecp5 for an ECP5-85F (CABGA381, speed grade 6) at FREQ MHz
# (default 100); fails when routed timing does not close. Then the whole board design is
# built to a bitstream for the ULX3S (`snapgen build --board ulx3s`: its PLL's clock, its
# pins), which fails the same way at the board's clock. nextpnr-ecp5 and ecppack come from
# PyPI when missing (scripts/ecp5-tools.sh). Prints each routed Fmax.
#
#   ./scripts/route.sh [FREQ]
#   ROUTE_ALL=1 ./scripts/route.sh    # also the steppers' blocks on their own
set -euo pipefail
cd "$(dirname "$0")/.."
freq="${1:-100}"

nextpnr="$(./scripts/ecp5-tools.sh)"

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
  local module="$1" label="$2" dir="$work/$1" start="$SECONDS"
  mkdir -p "$dir"
  python3 scripts/timing_wrap.py "$work/$module.v" "$module" >"$dir/timing_top.v"
  # Relative paths: the netlist's source attributes, which nextpnr's placement depends on,
  # then do not depend on the temporary directory's name (the result repeats anywhere).
  (cd "$dir" && yosys -q -p "read_verilog timing_top.v; synth_ecp5 -top timing_top -json timing_top.json") \
    >"$dir/yosys.log" 2>&1 || { tail -5 "$dir/yosys.log" >&2; exit 1; }
  # (The WebAssembly build sees only its working directory: relative paths.)
  local status=0
  (cd "$dir" && "$nextpnr" --85k --package CABGA381 --speed 6 --freq "$freq" --seed 1 \
    --json timing_top.json --sdf routed.sdf >nextpnr.log 2>&1) || status=$?
  # The routed report's last line: "Max frequency for clock '...': F MHz (PASS|FAIL at T MHz)",
  # after routing completed (the same line after placement is an estimate).
  local last
  last="$(sed -n '/Routing complete/,$p' "$dir/nextpnr.log" | grep -E "Max frequency for clock" | tail -1 || true)"
  if [ "$status" -ne 0 ] || ! grep -q "PASS at" <<<"$last"; then
    tail -5 "$dir/nextpnr.log" >&2
    if grep -q "FAIL at" <<<"$last"; then
      # The failing endpoints, by block (scripts/slack.py).
      python3 scripts/slack.py "$dir/routed.sdf" "$(python3 -c "print(1000 / $freq)")" 0 >&2 || true
      echo "$module ($label): routed timing does not close at $freq MHz on the ECP5-85F" >&2
    else
      echo "nextpnr-ecp5 failed (exit $status) on $module before reporting timing; its log's end is above" >&2
    fi
    exit 1
  fi
  local fmax
  fmax="$(grep -oE "[0-9.]+ MHz \(PASS" <<<"$last" | grep -oE "^[0-9.]+")"
  echo "$module ($label): routed Fmax $fmax MHz on the ECP5-85F (speed 6), target $freq MHz: closes ($((SECONDS - start)) s)"
  # Every endpoint's slack from the routed delays (scripts/slack.py): those within 0.5 ns of
  # the period, by block. Its worst slack must be nextpnr's (1/Fmax − period), or the
  # script misreads the SDF.
  local period report worst
  period="$(python3 -c "print(1000 / $freq)")"
  report="$(python3 scripts/slack.py "$dir/routed.sdf" "$period" 0.5)"
  sed 's/^/    /' <<<"$report"
  worst="$(grep -oE "worst [-+0-9.]+ ns$" <<<"$report" | grep -oE "[-+0-9.]+")"
  python3 -c "import sys; sys.exit(abs($period - 1000 / $fmax - $worst) > 0.01)" || {
    echo "scripts/slack.py's worst slack ($worst ns) is not nextpnr's ($fmax MHz at $freq MHz)" >&2
    exit 1
  }
}

# The path steppers instantiate the sequencer, the interpolator and the step/dir generators
# routed below on their own with ROUTE_ALL=1 (their own figures, for docs/PATH.md): when the
# steppers close, every path of theirs does.
if [ "${ROUTE_ALL:-0}" = 1 ]; then
  route snapgen_interpolator "4 axes"
  route snapgen_path_sequencer "4 axes"
  route snapgen_step_dir "one axis"
fi
# The blocks on their own in the background, the board design beside them (nextpnr runs on
# one core: the two take the machine's two), then their reports in order.
(
  route snapgen_path_steppers "4 axes: sequencer, interpolator, 4 step/dir generators"
  route snapgen_core "the motion core: sequencer, chain, stop unit"
) >"$work/blocks.out" 2>&1 &
blocks=$!
# The board design (I/O top, motion core, the PLL, the pins) to a bitstream, at the ULX3S's
# clock.
board=0
./target/release/snapgen build --board ulx3s --out "$work/ulx3s" >"$work/ulx3s.out" 2>&1 || board=$?
status=0
wait "$blocks" || status=$?
if [ "$status" -eq 0 ]; then cat "$work/blocks.out"; else cat "$work/blocks.out" >&2; fi
if [ "$board" -ne 0 ]; then
  # (The build directory goes with $work: its logs' ends here.)
  tail -3 "$work/ulx3s.out" >&2
  tail -5 "$work/ulx3s/nextpnr.log" "$work/ulx3s/yosys.log" >&2 2>/dev/null || true
else
  tail -1 "$work/ulx3s.out"
fi
[ "$status" -eq 0 ] && [ "$board" -eq 0 ]
