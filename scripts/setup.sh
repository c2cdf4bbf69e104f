#!/usr/bin/env bash
# Installs what snapgen's demo and tests need beside Rust, when it is missing: Verilator (the
# co-simulation and the lint), Yosys (synthesis), tclsh and dtc (the Zynq build's checks) and
# Python's venv (for the routed-timing
# check's nextpnr from PyPI), with apt-get (as root, or through sudo).
# Sourced by scripts/demo.sh and scripts/test.sh; safe to run again (installs nothing twice).
set -euo pipefail

if ! command -v cargo >/dev/null 2>&1; then
  echo "cargo is not installed: install Rust first (https://rustup.rs)" >&2
  exit 1
fi
need_apt=()
command -v verilator >/dev/null 2>&1 || need_apt+=(verilator)
command -v yosys >/dev/null 2>&1 || need_apt+=(yosys)
# The Zynq build's checks: its Vivado scripts run under a stand-in in tclsh, its device-tree
# overlay is compiled with dtc.
command -v tclsh >/dev/null 2>&1 || need_apt+=(tcl)
command -v dtc >/dev/null 2>&1 || need_apt+=(device-tree-compiler)
# Python with venv and pip: scripts/route.sh installs nextpnr-ecp5 from PyPI into a venv.
if ! command -v python3 >/dev/null 2>&1; then
  need_apt+=(python3 python3-venv)
elif ! python3 -c "import venv, ensurepip" >/dev/null 2>&1; then
  need_apt+=(python3-venv)
fi
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "installing ${need_apt[*]} with apt-get"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "apt-get is not available: install ${need_apt[*]} with your package manager" >&2
    exit 1
  fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi
