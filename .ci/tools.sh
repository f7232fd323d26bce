# The tools CI's steps install when they are missing, one function per step; sourced by the
# steps and by .ci/prefetch.sh. Each installs quietly and never fails: the step checks what it
# got and skips with a message only when a tool could not be installed.

have() { command -v "$1" >/dev/null 2>&1; }

# Debian packages, refreshing the package lists only when the first try fails.
apt_install() {
  if have apt-get; then
    (apt-get install -y "$@" >/dev/null 2>&1 \
      || { apt-get update >/dev/null 2>&1 && apt-get install -y "$@" >/dev/null 2>&1; }) || true
  fi
}

# .ci/cross.sh: QEMU user mode and the aarch64 linker, Node for WASI, both Rust targets.
cross_tools() {
  { have qemu-aarch64 && have aarch64-linux-gnu-gcc; } \
    || apt_install qemu-user gcc-aarch64-linux-gnu libc6-dev-arm64-cross
  have node || apt_install nodejs
  rustup target add aarch64-unknown-linux-gnu wasm32-wasip1 >/dev/null 2>&1 || true
}

# .ci/cortex-m.sh and .ci/nostd.sh: QEMU's Arm boards and the Cortex-M4F target.
cortex_tools() {
  have qemu-system-arm || apt_install qemu-system-arm
  rustup target add thumbv7em-none-eabihf >/dev/null 2>&1 || true
}

# .ci/capi.sh: the C and C++ compilers.
c_tools() {
  { have gcc && have g++; } || apt_install gcc g++
}

# .ci/python.sh: a virtualenv at $1 with the build tool and the tests' packages (kept when it
# has them: the prefetch made it).
python_env() {
  if [ -x "$1/bin/maturin" ] && "$1/bin/python" -c "import numpy, pytest, trimesh, rtree" 2>/dev/null; then
    return 0
  fi
  python3 -m venv "$1" \
    && "$1/bin/pip" install --quiet --upgrade pip \
    && "$1/bin/pip" install --quiet "maturin>=1.7,<2" numpy pytest trimesh rtree
}
