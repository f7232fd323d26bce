#!/usr/bin/env bash
# The same bits on other ISAs: test slices on aarch64 (NEON, under QEMU user mode) and on
# wasm32-wasip1 (simd128, under Node's WASI), through the runners in .cargo/config.toml. Each
# slice includes the determinism digest (the value stored for x86-64), the Cortex-M firmware's
# transcript (examples/cortex-m/expected.txt), the golden seed tests, the box test,
# packet == scalar twin, the exact tier against the oracle and BVH == brute force. Installs what
# it needs; skips a target with a message only when its tools cannot be installed here.
set -euo pipefail
cd "$(dirname "$0")/.."

. .ci/tools.sh
cross_tools

# The slice, as test-name filters on the one integration-test binary (tests/suite): whole
# modules, and BVH == brute force without the heaviest proptests (emulation is slow) and, on
# WebAssembly, without the thread-pool tests (wasm32-wasip1 has no threads).
SLICE=(determinism:: embedded:: golden:: exact:: queries:: packet_bits::
  bvh::bvh_equals_brute_force_on_triangle_scenes bvh::bvh_equals_brute_force_on_sphere_scenes
  bvh::filtered_walks bvh::ties_go_to bvh::crack_suite bvh::build_is_deterministic
  bvh::empty_and_unhittable bvh::refit_rejects)

# Under emulation the random tests run a quarter of their cases (OCTORAY_CASES, read by
# testkit::cases; the native and baseline runs above run them all); the fixed data (the
# determinism digest, the seed problems, the firmware's transcript) is the same.
export OCTORAY_CASES="${OCTORAY_CASES:-0.25}"

# The config's wasm runner names its script relative to the workspace, but cargo runs a
# package's unit tests from the package's folder: give it the absolute path.
export CARGO_TARGET_WASM32_WASIP1_RUNNER="node --no-warnings --single-threaded $PWD/.ci/wasi-run.mjs"

# Each target's flags (the slice's cfg; simd128 on WebAssembly). Set per target, they leave the
# build scripts and proc macros, built for this machine, as the other steps build them (a
# RUSTFLAGS from the environment would replace them: unset).
unset RUSTFLAGS CARGO_ENCODED_RUSTFLAGS
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUSTFLAGS="--cfg octoray_isa_slice"
export CARGO_TARGET_WASM32_WASIP1_RUSTFLAGS="-C target-feature=+simd128 --cfg octoray_isa_slice"

targets=()
if have qemu-aarch64 && have aarch64-linux-gnu-gcc && rustup target add aarch64-unknown-linux-gnu >/dev/null 2>&1; then
  targets+=(aarch64-unknown-linux-gnu)
else
  echo "skipped: aarch64 (qemu-user or the aarch64 linker could not be installed here)"
fi
if have node && node -e "require('node:wasi')" >/dev/null 2>&1 && rustup target add wasm32-wasip1 >/dev/null 2>&1; then
  targets+=(wasm32-wasip1)
else
  echo "skipped: wasm32-wasip1 (no Node with node:wasi could be installed here)"
fi
[ ${#targets[@]} -gt 0 ] || exit 0

# Both targets in one cargo run, so that their builds share the cores; cargo then runs each
# target's tests through its runner: the slice's modules of tests/suite and the box test, a unit
# test of octoray-packet (the slab test is internal). The filters select by name: no suite test
# is under `tree::box_test::`, no box test under the slice's modules.
echo "== test slices on: ${targets[*]}"
CARGO_TARGET_DIR=target/cross cargo test "${targets[@]/#/--target=}" \
  -p octoray -p octoray-packet --test suite --lib -- "${SLICE[@]}" tree::box_test::
echo "ok: slices passed on ${targets[*]} (digest equal to x86-64's)"
