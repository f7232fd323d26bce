#!/usr/bin/env bash
# The glam range: octoray accepts glam >=0.25, <0.35 (its public types are glam's `Vec3`), so a
# renderer on any of those versions hands octoray its own vectors. A consumer crate of its own
# (.ci/glam-range, not in the workspace) is resolved at each end of the range and its test run.
set -euo pipefail
cd "$(dirname "$0")/glam-range"
export CARGO_TARGET_DIR=../../target/glam-range
for end in lowest highest; do
  rm -f Cargo.lock
  cargo generate-lockfile --quiet
  if [ "$end" = lowest ]; then
    cargo update --quiet -p glam --precise 0.25.0
  fi
  version=$(cargo tree --quiet -e normal -i glam --depth 0 | awk '{print $2}')
  echo "== glam $version ($end end of the range)"
  cargo test --quiet
  # Depending on octoray leaves the application's glam on its own (std) math backend.
  if cargo tree --quiet -e features -i glam | grep -q 'glam feature "libm"'; then
    echo "error: octoray turned on glam's libm feature for the whole program" >&2
    exit 1
  fi
done
rm -f Cargo.lock
