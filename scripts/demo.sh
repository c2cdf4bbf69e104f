#!/usr/bin/env bash
# The main job on built-in defaults (README's first command): installs Verilator and Yosys
# when missing (scripts/setup.sh), then runs `snapgen demo`, which plans seed 001's and seed
# 000's moves, writes their plots, generates the Verilog, co-simulates it against the model
# and synthesises it (out/demo/).
#
#   ./scripts/demo.sh [demo options]      # e.g. --out DIR
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
exec cargo run --release -p snapgen-cli -- demo "$@"
