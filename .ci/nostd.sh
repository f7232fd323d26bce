#!/usr/bin/env bash
# The no_std proof: fails if `std` is anywhere in the dependency graph of octoray-core or
# octoray-packet.
#  1. A host `#![no_std]` staticlib with its own #[panic_handler] links both crates: a leaked std
#     makes it fail with E0152 (duplicate lang item `panic_impl`).
#  2. Both crates build for thumbv7em-none-eabihf, a target that has no std at all (skipped with
#     a message only when rustup cannot add the target on this machine).
set -euo pipefail
cd "$(dirname "$0")/.."
echo "== no_std: host staticlib with its own panic handler"
cargo build --quiet --manifest-path .ci/nostd-check/Cargo.toml --target-dir target/nostd-check
echo "ok: octoray-core + octoray-packet (kernels, BVH and scene traversal, alloc off) link into a #![no_std] staticlib"
echo "== the scalar core without wide"
cargo build --quiet -p octoray-core --no-default-features --features libm
cargo build --quiet -p octoray-core --no-default-features --features triangle,sphere,alloc,libm
if cargo tree -p octoray-core --no-default-features --features triangle,sphere,alloc,libm -e normal --prefix none | grep -q '^wide '; then
  echo "error: wide is in octoray-core's dependency graph without the wide feature" >&2
  exit 1
fi
echo "ok: octoray-core builds without wide (cargo tree shows no wide)"
echo "== no_std: thumbv7em-none-eabihf"
if rustup target list --installed 2>/dev/null | grep -qx thumbv7em-none-eabihf \
   || rustup target add thumbv7em-none-eabihf >/dev/null 2>&1; then
  cargo build --quiet -p octoray-core -p octoray-packet --no-default-features --features triangle,sphere,alloc,libm --target thumbv7em-none-eabihf
  cargo build --quiet -p octoray-core --no-default-features --features triangle,sphere,libm --target thumbv7em-none-eabihf
  echo "ok: octoray-core (with and without alloc) + octoray-packet (SIMD kernels and BVH traversal) build for thumbv7em-none-eabihf"
else
  echo "skipped: rustup could not add thumbv7em-none-eabihf here (the staticlib check above still ran)"
fi
