#!/usr/bin/env bash
# Seed 001's host is a Raspberry Pi: the host side of snapgen must plan exactly what an x86
# host plans. This cross-builds `snapgen` for 64-bit ARM Linux (aarch64-unknown-linux-gnu),
# runs `snapgen plan --json` under user-mode emulation (Debian's qemu-user) for a fixed set of
# moves of every method and 60 seeded random ones, and checks that every plan is byte-identical
# to the x86 build's. Installs what it needs (rustup target, cross gcc, qemu-user) when missing.
#
#   ./scripts/arm64.sh            # called by scripts/test.sh
#
# (`snapgen send` cross-builds too, but qemu-user 7.2 does not implement the TCGETS2 ioctl the
# serial port library uses to set a baud rate, so it cannot open a port under emulation; on a
# real ARM board it can.)
set -euo pipefail
cd "$(dirname "$0")/.."

target=aarch64-unknown-linux-gnu
need_apt=()
command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 || need_apt+=(gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v qemu-aarch64 >/dev/null 2>&1 || need_apt+=(qemu-user)
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "installing ${need_apt[*]} with apt-get"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi
rustup target list --installed 2>/dev/null | grep -qx "$target" || rustup target add "$target"

echo "== cross-building snapgen for $target"
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
# The build directories follow CARGO_TARGET_DIR when it is set.
tdir=${CARGO_TARGET_DIR:-target}
CARGO_TARGET_DIR=$tdir/arm64 cargo build --release --quiet --target "$target" -p snapgen-cli
cargo build --release --quiet -p snapgen-cli
arm=$tdir/arm64/$target/release/snapgen
x86=$tdir/release/snapgen
# ELF e_machine (bytes 18-19) is 0xB7 for AArch64.
[ "$(od -An -tx1 -j18 -N2 "$arm" | tr -d ' ')" = "b700" ] || { echo "$arm is not an aarch64 binary" >&2; exit 1; }

moves=(
  "--order 4 --distance 0.5 --vmax 1 --amax 5 --jmax 50 --dmax 1000"
  "--order 4 --distance -1200 --vmax 0.1 --amax 1 --jmax 10 --dmax 100"
  "--order 4 --distance 9e-3 --vmax 1 --amax 300 --jmax 2e5 --dmax 1e9 --ts 1e-3"
  "--order 3 --distance -0.2 --vmax 1 --amax 5 --jmax 50"
  "--order 3 --distance 2000 --vmax 500 --amax 1e4 --jmax 1e6"
  "--order 2 --distance 3 --vmax 1 --amax 4"
  "--order 2 --distance -1e-6 --vmax 1 --amax 10"
  "--distance 37.69911184307752 --duration 1.8 --gamma 0.4 --phi 0.25"
  "--distance -37.69911184307752 --duration 1.8 --gamma 0.4 --phi 0.25"
)
# Seeded random moves (bash's generator is deterministic for a given seed).
RANDOM=9
lu() { # log-uniform in [10^$1, 10^$2] from two $RANDOM draws
  awk -v a="$1" -v b="$2" -v r="$RANDOM" -v s="$RANDOM" \
    'BEGIN { u = (r * 32768 + s) / 1073741824; printf "%.9g", 10 ^ (a + u * (b - a)) }'
}
for _ in $(seq 1 20); do
  sign=$([ $((RANDOM % 2)) -eq 0 ] && echo "" || echo "-")
  moves+=("--order 4 --distance $sign$(lu -4 1) --vmax $(lu -1 1) --amax $(lu 0 2) --jmax $(lu 1 4) --dmax $(lu 3 6)")
  moves+=("--order 3 --distance $sign$(lu -4 1) --vmax $(lu -1 1) --amax $(lu 0 2) --jmax $(lu 1 4)")
  moves+=("--order 2 --distance $sign$(lu -4 1) --vmax $(lu -1 1) --amax $(lu 0 2)")
done

echo "== planning ${#moves[@]} moves on $target under qemu-user and on $(uname -m)"
same=0
for m in "${moves[@]}"; do
  # shellcheck disable=SC2086
  a=$(qemu-aarch64 -L /usr/aarch64-linux-gnu "$arm" plan --json $m 2>&1) || true
  # shellcheck disable=SC2086
  b=$("$x86" plan --json $m 2>&1) || true
  if [ "$a" != "$b" ]; then
    echo "DIFFERENT plans for: snapgen plan $m" >&2
    diff <(echo "$b") <(echo "$a") | head -20 >&2
    exit 1
  fi
  case "$b" in *'"segments"'*) same=$((same + 1)) ;; esac
done
echo "arm64: ${#moves[@]} moves, $same plans byte-identical to $(uname -m) (the rest identical refusals)"
[ "$same" -ge 60 ] || { echo "too few moves planned ($same)" >&2; exit 1; }
