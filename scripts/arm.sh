#!/usr/bin/env bash
# The host on ARM. Seed 001's host is a Raspberry Pi (64-bit ARM: aarch64-unknown-linux-gnu);
# a Zynq-7000's own processor, the Zybo's Cortex-A9, runs 32-bit ARM Linux
# (armv7-unknown-linux-gnueabihf). The host side of snapgen must do there exactly what it does
# on x86. For each target this cross-builds `snapgen` and, under user-mode emulation (Debian's
# qemu-user):
#   * plans a fixed set of moves of every method and 60 seeded random ones (`snapgen plan
#     --json`) and checks every plan byte-identical to the x86 build's;
#   * runs a short online script (examples/online_short.toml: a move, a feed override, an
#     aborting move) through the PLCopen host axis and the UIO link's register transport on the
#     simulated memory map of the AXI4-Lite board's model (`snapgen online --board axi-model
#     --json`: the same code as on a Zynq up to the mmap) and checks its whole report (outcomes,
#     latencies, final registers, board states checked) byte-identical to the x86 build's.
# Installs what it needs (rustup targets, cross gcc, qemu-user) when missing.
#
#   ./scripts/arm.sh                  # both targets; called by scripts/test.sh
#   ./scripts/arm.sh aarch64          # one (aarch64 or armv7)
#
# (`snapgen send` over a serial port cross-builds too, but qemu-user 7.2 does not implement the
# TCGETS2 ioctl the serial port library uses to set a baud rate, so it cannot open a port under
# emulation; on a real ARM board it can.)
set -euo pipefail
cd "$(dirname "$0")/.."

targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(aarch64 armv7)
# Per target: Rust's triple, the cross gcc and its Debian packages, qemu-user's binary and
# sysroot, the ELF e_machine (bytes 18-19 of the binary). Both targets build in the workspace's
# target directory (target/TRIPLE), so the build scripts and proc macros that run on this
# machine are the x86 build's, not built again.
triple() { case "$1" in aarch64) echo aarch64-unknown-linux-gnu ;; armv7) echo armv7-unknown-linux-gnueabihf ;; *) echo "unknown target $1: aarch64 or armv7" >&2; exit 2 ;; esac; }
gcc_of() { case "$1" in aarch64) echo aarch64-linux-gnu-gcc ;; armv7) echo arm-linux-gnueabihf-gcc ;; esac; }
debs_of() { case "$1" in aarch64) echo gcc-aarch64-linux-gnu libc6-dev-arm64-cross ;; armv7) echo gcc-arm-linux-gnueabihf libc6-dev-armhf-cross ;; esac; }
qemu_of() { case "$1" in aarch64) echo "qemu-aarch64 -L /usr/aarch64-linux-gnu" ;; armv7) echo "qemu-arm -L /usr/arm-linux-gnueabihf" ;; esac; }
machine_of() { case "$1" in aarch64) echo b700 ;; armv7) echo 2800 ;; esac; }

need_apt=()
for t in "${targets[@]}"; do
  triple "$t" >/dev/null
  # shellcheck disable=SC2207
  command -v "$(gcc_of "$t")" >/dev/null 2>&1 || need_apt+=($(debs_of "$t"))
done
command -v qemu-aarch64 >/dev/null 2>&1 && command -v qemu-arm >/dev/null 2>&1 || need_apt+=(qemu-user)
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "installing ${need_apt[*]} with apt-get"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

# The build directories follow CARGO_TARGET_DIR when it is set.
tdir=${CARGO_TARGET_DIR:-target}
cargo build --release --quiet -p snapgen-cli
x86=$tdir/release/snapgen

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


for t in "${targets[@]}"; do
  target=$(triple "$t")
  rustup target list --installed 2>/dev/null | grep -qx "$target" || rustup target add "$target"
  echo "== cross-building snapgen for $target"
  linker_var="CARGO_TARGET_$(echo "$target" | tr 'a-z-' 'A-Z_')_LINKER"
  env "$linker_var=$(gcc_of "$t")" \
    cargo build --release --quiet --target "$target" -p snapgen-cli
  arm=$tdir/$target/release/snapgen
  [ "$(od -An -tx1 -j18 -N2 "$arm" | tr -d ' ')" = "$(machine_of "$t")" ] || { echo "$arm is not an $t binary" >&2; exit 1; }
  read -r -a qemu <<<"$(qemu_of "$t")"

  echo "== planning ${#moves[@]} moves on $target under qemu-user and on $(uname -m)"
  same=0
  for m in "${moves[@]}"; do
    # shellcheck disable=SC2086
    a=$("${qemu[@]}" "$arm" plan --json $m 2>&1) || true
    # shellcheck disable=SC2086
    b=$("$x86" plan --json $m 2>&1) || true
    if [ "$a" != "$b" ]; then
      echo "DIFFERENT plans for: snapgen plan $m" >&2
      diff <(echo "$b") <(echo "$a") | head -20 >&2
      exit 1
    fi
    case "$b" in *'"segments"'*) same=$((same + 1)) ;; esac
  done
  echo "$t: ${#moves[@]} moves, $same plans byte-identical to $(uname -m) (the rest identical refusals)"
  [ "$same" -ge 60 ] || { echo "too few moves planned ($same)" >&2; exit 1; }

  echo "== the host axis over the UIO link's registers on the simulated AXI board, on $target under qemu-user"
  online=(online --script examples/online_short.toml --board axi-model --json)
  a=$("${qemu[@]}" "$arm" "${online[@]}" 2>&1) || { echo "$a" >&2; exit 1; }
  b=$("$x86" "${online[@]}" 2>&1) || { echo "$b" >&2; exit 1; }
  if [ "$a" != "$b" ]; then
    echo "DIFFERENT online reports on $target and $(uname -m)" >&2
    diff <(echo "$b") <(echo "$a") | head -20 >&2
    exit 1
  fi
  case "$b" in *'"state_checks"'*) ;; *) echo "no online report: $b" >&2; exit 1 ;; esac
  echo "$t: snapgen online over the simulated AXI board: report byte-identical to $(uname -m) ($(grep -o '"state_checks": [0-9]*' <<<"$b"), $(grep -o '"ticks": [0-9]*' <<<"$b"))"
done
