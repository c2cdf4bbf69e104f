#!/usr/bin/env bash
# The Python package (python/, PyO3 + maturin, abi3): builds its wheel, installs it into a
# venv in the snapgen cache (with NumPy and pytest from PyPI, pinned) and runs its tests
# (python/tests). Part of the test command. With --aarch64 it also cross-builds the aarch64
# wheel with the cross toolchain scripts/arm.sh installs; with --aarch64-run it then runs the
# tests on that wheel under qemu-user, in Debian's aarch64 CPython 3.11 (its packages
# unpacked, not installed, into the snapgen cache; `dpkg --add-architecture arm64` once) with
# NumPy's and pytest's aarch64 wheels from PyPI: every test but the Verilated boards' (their
# library is built for this x86 machine). Both are left out of the test command for their
# time (the build takes minutes, the emulated run about 7).
#
#   ./scripts/python.sh               # build, install, test
#   ./scripts/python.sh --aarch64     # ... and the aarch64 wheel (into target/wheels-arm64)
#   ./scripts/python.sh --aarch64-run # ... and its tests under qemu-user
#   ./scripts/python.sh --wheel       # build the x86_64 wheel only (into target/wheels)
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  "" | --wheel | --aarch64 | --aarch64-run) ;;
  *) echo "unknown option $1: give none, --wheel, --aarch64 or --aarch64-run" >&2; exit 2 ;;
esac

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

if [ "${1:-}" != "--aarch64" ] && [ "${1:-}" != "--aarch64-run" ]; then
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
  echo "built $arm (aarch64)"
  if [ "$1" = "--aarch64-run" ]; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    if ! command -v qemu-aarch64 >/dev/null; then
      $SUDO apt-get update -qq
      DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq qemu-user >/dev/null
    fi
    # Debian 12's aarch64 CPython and the libraries it links, unpacked (not installed) into a
    # root for qemu -L; built in a temporary directory and moved into place whole.
    root="$cache/aarch64-python-3.11"
    if [ ! -x "$root/usr/bin/python3.11" ]; then
      grep -q '^VERSION_CODENAME=bookworm' /etc/os-release || {
        echo "--aarch64-run unpacks Debian 12 (bookworm) packages: this is not Debian 12" >&2
        exit 1
      }
      if ! dpkg --print-foreign-architectures | grep -qx arm64; then
        echo "adding dpkg's arm64 architecture (its package lists; nothing is installed)"
        $SUDO dpkg --add-architecture arm64
      fi
      $SUDO apt-get update -qq
      unpack="$(mktemp -d "$cache/aarch64-python.XXXXXX")"
      trap 'rm -rf "$unpack"' EXIT
      mkdir "$unpack/debs" "$unpack/root"
      (cd "$unpack/debs" && apt-get -o APT::Sandbox::User=root download -q \
        python3.11-minimal:arm64 libpython3.11-minimal:arm64 \
        libpython3.11-stdlib:arm64 libc6:arm64 libgcc-s1:arm64 libstdc++6:arm64 libexpat1:arm64 \
        zlib1g:arm64 libffi8:arm64 libssl3:arm64 libbz2-1.0:arm64 liblzma5:arm64 \
        libsqlite3-0:arm64 libncursesw6:arm64 libtinfo6:arm64 libreadline8:arm64 libuuid1:arm64 \
        libdb5.3:arm64 libnsl2:arm64 libtirpc3:arm64 libcrypt1:arm64 libgssapi-krb5-2:arm64 \
        libkrb5-3:arm64 libk5crypto3:arm64 libkrb5support0:arm64 libcom-err2:arm64 \
        libkeyutils1:arm64 >/dev/null)
      for d in "$unpack"/debs/*.deb; do dpkg -x "$d" "$unpack/root"; done
      rm -rf "$root"
      mv "$unpack/root" "$root"
      rm -rf "$unpack"
      trap - EXIT
    fi
    # NumPy's and pytest's aarch64 wheels (the same pins), the snapgen wheel beside them.
    site="$(mktemp -d)"
    trap 'rm -rf "$site"' EXIT
    "$venv/bin/pip" download -q --only-binary=:all: --platform manylinux2014_aarch64 \
      --python-version 3.11 --implementation cp -d "$site/wheels" \
      "numpy==$numpy_version" "pytest==$pytest_version"
    for w in "$site"/wheels/*.whl "$arm"; do "$venv/bin/python" -m zipfile -e "$w" "$site/lib"; done
    machine="$(qemu-aarch64 -L "$root" "$root/usr/bin/python3.11" -c "import platform; print(platform.machine())")"
    [ "$machine" = "aarch64" ] || { echo "the emulated Python reports $machine, not aarch64" >&2; exit 1; }
    # The Verilated boards' tests (marker `verilated`) load a library built for this machine.
    PYTHONPATH="$site/lib" qemu-aarch64 -L "$root" "$root/usr/bin/python3.11" -m pytest -q \
      -p no:cacheprovider -m "not verilated" python/tests
    echo "ran the tests on $arm under qemu-user (aarch64 CPython 3.11), the Verilated boards' left out"
  fi
else
  echo "no aarch64 cross toolchain: run scripts/arm.sh first (it installs it)" >&2
  exit 1
fi
