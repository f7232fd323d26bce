#!/usr/bin/env bash
# The Python package: its wheel built with maturin in a virtualenv, installed, and its tests run
# with pytest (against trimesh's own ray interface too). Installs what it needs from PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=$root/target/python-venv
. .ci/tools.sh
python_env "$venv"
# Its crate is outside the main workspace: formatted and linted here.
(cd python && cargo fmt --check && CARGO_TARGET_DIR="$root/target/python" \
  cargo clippy --quiet --all-targets -- -D warnings)
rm -rf "$root/target/wheels"
# The extension's own workspace, its build output under target/ like the rest.
(cd python && CARGO_TARGET_DIR="$root/target/python" \
  "$venv/bin/maturin" build --release --quiet -o "$root/target/wheels")
"$venv/bin/pip" install --quiet --force-reinstall "$root"/target/wheels/octoray-*.whl
# From the tests' folder, so that the installed package is imported, not python/octoray/.
(cd python/tests && "$venv/bin/python" -m pytest -q -p no:cacheprovider .)
