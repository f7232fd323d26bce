#!/usr/bin/env bash
# octoray on a microcontroller: builds the Cortex-M4F firmware (examples/cortex-m) for
# thumbv7em-none-eabihf and runs it on QEMU's mps2-an386 board. The firmware solves the seed
# sheet's problems and traces a tree the host stored as bytes; its transcript must equal
# examples/cortex-m/expected.txt, which the host's own run of the same job must equal too
# (tests/suite/embedded.rs). Then the one-tier firmwares run and their sizes are printed.
#   bash .ci/cortex-m.sh           the check (in .ci/run)
#   bash .ci/cortex-m.sh --report  also rewrites benches/cortex-m.md (figures and sizes)
# Installs what it needs; skips with a message only when QEMU or the target cannot be installed.
set -euo pipefail
cd "$(dirname "$0")/.."
. .ci/tools.sh
cortex_tools
if ! have qemu-system-arm || ! rustup target add thumbv7em-none-eabihf >/dev/null 2>&1; then
  echo "skipped: Cortex-M run (qemu-system-arm or the thumbv7em-none-eabihf target could not be installed here)"
  exit 0
fi

fw=examples/cortex-m
export CARGO_TARGET_DIR="$PWD/target/cortex-m"
# Cargo reads the firmware's .cargo/config.toml (target, runner, linker script) from the
# directory it runs in.
(
  cd "$fw"
  cargo fmt -- --check
  cargo clippy --quiet --release --bins -- -D warnings
  cargo build --quiet --release --bins
)
bin="$CARGO_TARGET_DIR/thumbv7em-none-eabihf/release"
# The runner of examples/cortex-m/.cargo/config.toml, with a time limit.
run() {
  timeout 300 qemu-system-arm -machine mps2-an386 -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0 -kernel "$bin/$1"
}

echo "== the firmware on a Cortex-M4F (QEMU mps2-an386)"
out=$(run octoray-cortex-m) || { echo "$out"; echo "error: the firmware failed its own checks" >&2; exit 1; }
echo "$out"
if ! diff <(grep -v '^#' <<<"$out") "$fw/expected.txt"; then
  echo "error: the Cortex-M transcript differs from examples/cortex-m/expected.txt (the host's)" >&2
  exit 1
fi
echo "ok: the Cortex-M4F's transcript and digest equal the host's"

echo "== one tier per firmware"
sizes=()
for tier in standard watertight exact; do
  run "tier-$tier"
  # text + rodata (code and constants in flash, the stored tree included) and the tree's bytes.
  read -r text rodata < <(size -A "$bin/tier-$tier" | awk '$1==".text"{t=$2} $1==".rodata"{r=$2} END{print t, r}')
  sizes+=("$tier $text $rodata")
  echo "$tier: .text $text bytes, .rodata $rodata bytes"
done

if [ "${1:-}" = --report ]; then
  vertex=$(stat -c %s "$(ls -t "$CARGO_TARGET_DIR"/thumbv7em-none-eabihf/release/build/octoray-cortex-m-*/out/vertex.bin | head -1)")
  packed=$(stat -c %s "$(ls -t "$CARGO_TARGET_DIR"/thumbv7em-none-eabihf/release/build/octoray-cortex-m-*/out/packed.bin | head -1)")
  {
    echo "# octoray on a Cortex-M4F"
    echo
    echo "Written by \`bash .ci/cortex-m.sh --report\`: the firmware of \`examples/cortex-m\` built for"
    echo "\`thumbv7em-none-eabihf\` (release, LTO, \`opt-level = 3\`; $(rustc --version | cut -d' ' -f1-2)) and run on"
    echo "$(qemu-system-arm --version | head -1 | sed 's/ (.*//') \`-machine mps2-an386 -icount shift=0\`. Instruction counts are QEMU's"
    echo "(SysTick under \`-icount\`, exact to 40 instructions per span); they depend on the compiler, not the host."
    echo
    echo "<!-- cortex-m:begin -->"
    echo "| figure | standard | watertight | exact |"
    echo "|---|---|---|---|"
    grep '^# instructions per ray-triangle' <<<"$out" | sed -E 's/.*standard ([0-9]+), watertight ([0-9]+), exact ([0-9]+)/| instructions per ray-triangle test (closest of 256) | \1 | \2 | \3 |/'
    grep '^# instructions per ray through' <<<"$out" | sed -E 's/.*\(([0-9]+) triangles.*standard ([0-9]+), watertight ([0-9]+), exact ([0-9]+)/| instructions per ray through a stored tree (\1 triangles, closest) | \2 | \3 | \4 |/'
    line="| code of a one-tier firmware (\`.text\`, bytes) |"
    for s in "${sizes[@]}"; do read -r _ t _ <<<"$s"; line+=" $t |"; done
    echo "$line"
    echo "| the stored tree (bytes, in \`.rodata\`) | $packed | $vertex | $vertex |"
    echo "<!-- cortex-m:end -->"
  } > benches/cortex-m.md
  echo "wrote benches/cortex-m.md"
fi
