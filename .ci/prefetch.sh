#!/usr/bin/env bash
# Installs every later CI step's tools (.ci/tools.sh) ahead of time: .ci/run starts this in the
# background while the first steps compile, since downloading and unpacking wait on the network
# and the disk, not on the cores. Never fails; each step still installs what is missing.
cd "$(dirname "$0")/.."
. .ci/tools.sh
cross_tools
cortex_tools
c_tools
python_env "$PWD/target/python-venv" || true
echo "prefetch: done"
