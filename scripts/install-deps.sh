#!/usr/bin/env bash
# Installs what building bulge needs when it is missing: the system OpenCV
# (libopencv-dev: its pkg-config file is what the opencv crate probes), clang/libclang (the opencv crate generates its
# bindings with it) and pkg-config; and Python 3 with venv, in which the
# Python package is built and tested. Debian/Ubuntu through apt-get (as root or
# with sudo), macOS through Homebrew; otherwise it names the packages.
set -euo pipefail

APT_PACKAGES=(clang libclang-dev pkg-config libopencv-dev python3 python3-venv)
BREW_PACKAGES=(opencv llvm pkg-config python3)

have_opencv() { command -v pkg-config >/dev/null 2>&1 && pkg-config --exists opencv4; }
have_libclang() {
  compgen -G '/usr/lib/llvm-*/lib/libclang*.so*' >/dev/null ||
    compgen -G '/usr/lib/x86_64-linux-gnu/libclang*.so*' >/dev/null ||
    compgen -G '/usr/lib/aarch64-linux-gnu/libclang*.so*' >/dev/null ||
    compgen -G '/opt/homebrew/opt/llvm/lib/libclang.dylib' >/dev/null ||
    compgen -G '/usr/local/opt/llvm/lib/libclang.dylib' >/dev/null
}
# venv with ensurepip: Debian ships them apart from python3 (python3-venv).
have_venv() { command -v python3 >/dev/null 2>&1 && python3 -c 'import venv, ensurepip' >/dev/null 2>&1; }

if ! command -v cargo >/dev/null 2>&1; then
  echo "install-deps: cargo is not on PATH; install the Rust toolchain (https://rustup.rs) first." >&2
  exit 1
fi

if have_opencv && have_libclang && have_venv; then
  echo "install-deps: OpenCV $(pkg-config --modversion opencv4), libclang and Python 3 with venv are present."
  exit 0
fi

if command -v apt-get >/dev/null 2>&1; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
      echo "install-deps: not root and no sudo; install as root: apt-get install ${APT_PACKAGES[*]}" >&2
      exit 1
    fi
  fi
  echo "install-deps: installing ${APT_PACKAGES[*]} with apt-get"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${APT_PACKAGES[@]}" >/dev/null
elif command -v brew >/dev/null 2>&1; then
  echo "install-deps: installing ${BREW_PACKAGES[*]} with Homebrew"
  brew install "${BREW_PACKAGES[@]}"
else
  echo "install-deps: no apt-get or brew here. Install OpenCV 4 (core, imgproc, imgcodecs) with its pkg-config file, clang and libclang, and Python 3 with venv, then run make again." >&2
  exit 1
fi

if ! have_opencv || ! have_libclang || ! have_venv; then
  echo "install-deps: OpenCV, libclang or Python 3's venv still missing after the install; see the messages above." >&2
  exit 1
fi
echo "install-deps: OpenCV $(pkg-config --modversion opencv4), libclang and Python 3 with venv are present."
