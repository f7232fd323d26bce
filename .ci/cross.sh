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

# slice TARGET NAME RUSTFLAGS: the slice for TARGET, built in its own target dir with only the
# slice's modules of tests/suite, and the box test, a unit test of octoray-packet (the slab test
# is internal), in one cargo run so the two builds share the cores (RUSTFLAGS applies to the
# target's artifacts only, and replaces the config's flags for it). The filters select by name:
# no suite test is under `tree::box_test::`, no box test under the slice's modules.
slice() {
  CARGO_TARGET_DIR=target/cross RUSTFLAGS="$3 --cfg octoray_isa_slice" \
    cargo test --target "$1" -p octoray -p octoray-packet --test suite --lib -- \
    "${SLICE[@]}" tree::box_test::
  echo "ok: $2 slice passed (digest equal to x86-64's)"
}

echo "== aarch64 (NEON) under QEMU user mode"
if have qemu-aarch64 && have aarch64-linux-gnu-gcc && rustup target add aarch64-unknown-linux-gnu >/dev/null 2>&1; then
  slice aarch64-unknown-linux-gnu aarch64 ""
else
  echo "skipped: aarch64 (qemu-user or the aarch64 linker could not be installed here)"
fi

echo "== wasm32-wasip1 (simd128) under Node's WASI"
if have node && node -e "require('node:wasi')" >/dev/null 2>&1 && rustup target add wasm32-wasip1 >/dev/null 2>&1; then
  slice wasm32-wasip1 wasm32-wasip1 "-C target-feature=+simd128"
else
  echo "skipped: wasm32-wasip1 (no Node with node:wasi could be installed here)"
fi
