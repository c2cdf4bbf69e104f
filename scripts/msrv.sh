#!/usr/bin/env bash
# Keeps the workspace's rust-version (Cargo.toml) true: checks every crate but the oracle
# tests (snapgen-tests, which need rsruckig's Rust 1.87) with exactly that Rust, installed
# with rustup when missing. Dependencies resolve to versions that support it
# (.cargo/config.toml: incompatible-rust-versions = "fallback").
set -euo pipefail
cd "$(dirname "$0")/.."
msrv=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml)
[ -n "$msrv" ] || { echo "no rust-version in Cargo.toml" >&2; exit 1; }
rustup toolchain list | grep -q "^$msrv" || rustup toolchain install "$msrv" --profile minimal >/dev/null
echo "== cargo +$msrv check (rust-version $msrv)"
CARGO_TARGET_DIR=target/msrv cargo "+$msrv" check --quiet --workspace --exclude snapgen-tests --all-targets
echo "rust-version $msrv: every crate but snapgen-tests checks with Rust $msrv"
