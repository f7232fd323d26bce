#!/usr/bin/env bash
# The C ABI from C and C++: builds octoray-capi's static library, compiles capi/examples/trace.c
# (gcc) and trace.cpp (g++) against the committed header capi/include/octoray.h, runs both at
# every tier and checks that each prints what the Rust API prints for the same job
# (capi/examples/digest.rs); then both render the demo's embedded scene, exported by that
# example as `render --export` writes it, and must print the Rust API's digest of its primary
# hits on the stored scene (the demo's tests check that this is the digest the demo renders). The header's freshness is checked by the test suite
# (capi/tests/header.rs). Installs gcc/g++ when missing; skips with a message only when they
# cannot be installed.
set -euo pipefail
cd "$(dirname "$0")/.."
. .ci/tools.sh
c_tools
if ! have gcc || ! have g++; then
  echo "skipped: the C and C++ examples (gcc/g++ could not be installed here)"
  exit 0
fi

# The test profile and the workspace's feature set: what `cargo test --workspace` built already
# (a narrower selection would resolve other features and rebuild). Not the demo's `render`
# binary, which instantiates the tracer at every tier and width.
cargo build --quiet --profile test --workspace --lib --examples
lib=target/debug/liboctoray_capi.a
out=target/capi
mkdir -p "$out"
# -ffp-contract=off: the job's camera arithmetic rounds as Rust's does (no fused multiply-add).
flags=(-O2 -Wall -Wextra -Werror -ffp-contract=off -Icapi/include)
libs=(-lm -lpthread -ldl)
gcc -std=c11 "${flags[@]}" capi/examples/trace.c "$lib" "${libs[@]}" -o "$out/trace-c"
g++ -std=c++17 "${flags[@]}" capi/examples/trace.cpp "$lib" "${libs[@]}" -o "$out/trace-cpp"
for tier in 0 1 2; do
  rust=$(target/debug/examples/digest "$tier")
  c=$("$out/trace-c" "$tier")
  cpp=$("$out/trace-cpp" "$tier")
  echo "rust: $rust"
  echo "c:    $c"
  echo "c++:  $cpp"
  if [ "$c" != "$rust" ] || [ "$cpp" != "$rust" ]; then
    echo "error: the C ABI's answers differ from the Rust API's at tier $tier" >&2
    exit 1
  fi
done
echo "ok: C and C++ through the C ABI print the Rust API's answers and digests at every tier"

w=160 h=100
for tier in standard:0 watertight:1 exact:2; do
  name=${tier%%:*} num=${tier##*:}
  demo=$(target/debug/examples/digest demo "$out/demo-$name" "$num" "$w" "$h")
  for prog in trace-c trace-cpp; do
    line=$("$out/$prog" demo "$out/demo-$name" "$num" "$w" "$out/demo-$name-$prog.ppm")
    echo "$prog: $line (Rust API: $demo)"
    if [ -z "$demo" ] || [ "${line##* digest }" != "$demo" ]; then
      echo "error: $prog's render of the demo scene differs from the Rust API's at tier $name" >&2
      exit 1
    fi
  done
done
echo "ok: C and C++ render the demo's embedded scene with the Rust API's primary-hit digest at every tier"
