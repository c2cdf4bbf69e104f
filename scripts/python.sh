#!/usr/bin/env bash
# The Python package (python/, PyO3 + maturin, abi3): builds its wheel, installs it into a
# venv in the snapgen cache (with NumPy and pytest from PyPI, pinned) and runs its tests
# (python/tests). Part of the test command. With --aarch64 it also cross-builds the aarch64
# wheel with the cross toolchain scripts/arm.sh installs (built, not run: there is no aarch64
# Python here; left out of the test command for its time).
#
#   ./scripts/python.sh             # build, install, test
#   ./scripts/python.sh --aarch64   # ... and the aarch64 wheel (into target/wheels-arm64)
#   ./scripts/python.sh --wheel     # build the x86_64 wheel only (into target/wheels)
set -euo pipefail
cd "$(dirname "$0")/.."

maturin_version="1.7.4"
numpy_version="2.1.3"
pytest_version="8.3.3"
cache="${SNAPGEN_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/snapgen}"
venv="$cache/python-$maturin_version-$numpy_version-$pytest_version"
if [ ! -x "$venv/bin/pytest" ] || [ ! -x "$venv/bin/maturin" ]; then
  echo "installing maturin $maturin_version, numpy $numpy_version, pytest $pytest_version (PyPI) into $venv"
  if ! python3 -m venv "$venv"; then
    echo "python3 -m venv failed: install Python's venv module (Debian: apt-get install python3-venv)" >&2
    exit 1
  fi
  "$venv/bin/pip" install -q "maturin==$maturin_version" "numpy==$numpy_version" "pytest==$pytest_version"
fi

rm -rf target/wheels
"$venv/bin/maturin" build --release --quiet --strip -m python/Cargo.toml -o target/wheels -i "$venv/bin/python"
wheel="$(ls target/wheels/snapgen-*.whl)"
echo "built $wheel"
if [ "${1:-}" = "--wheel" ]; then
  exit 0
fi
"$venv/bin/pip" install -q --force-reinstall --no-deps "$wheel"
"$venv/bin/python" -m pytest -q python/tests

if [ "${1:-}" != "--aarch64" ]; then
  exit 0
fi
target=aarch64-unknown-linux-gnu
if command -v aarch64-linux-gnu-gcc >/dev/null && rustup target list --installed 2>/dev/null | grep -qx "$target"; then
  rm -rf target/wheels-arm64
  CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc \
    CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-target}/arm64" \
    "$venv/bin/maturin" build --release --quiet --strip -m python/Cargo.toml --target "$target" -o target/wheels-arm64
  arm="$(ls target/wheels-arm64/snapgen-*aarch64.whl)"
  # The extension inside is an AArch64 ELF (e_machine, bytes 18-19: 0xB7).
  machine="$("$venv/bin/python" -c "import sys, zipfile; z = zipfile.ZipFile(sys.argv[1]); so = [n for n in z.namelist() if n.endswith('.so')][0]; print(z.read(so)[18:20].hex())" "$arm")"
  [ "$machine" = "b700" ] || { echo "$arm: the extension is not an aarch64 binary ($machine)" >&2; exit 1; }
  echo "built $arm (aarch64, not run here)"
else
  echo "no aarch64 cross toolchain: run scripts/arm.sh first (it installs it)" >&2
  exit 1
fi
