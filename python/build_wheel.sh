#!/usr/bin/env bash
# Builds the distributable wheel: one abi3 file for every CPython from 3.9 on that
# installs on any x86_64 Linux with glibc 2.17 or newer (tag manylinux2014 /
# manylinux_2_17; CentOS 7, RHEL 8 and 9, Ubuntu 18.04 and later, Debian 10 and later).
#
#     bash python/build_wheel.sh [OUTDIR]        # default: dist/
#
# maturin links the extension with zig's linker against glibc 2.17's symbols (no
# container needed) and checks the result against the manylinux policy; it fails rather
# than writing a wheel with newer symbols. maturin and zig are installed into a private
# virtual environment under the cargo target folder, not into the active one. Needs
# python3 (3.9+), cargo and the network for the first run.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$(realpath -m "${1:-$root/dist}")"
target="${CARGO_TARGET_DIR:-$root/target}"
tools="$target/wheel-tools"
[ -x "$tools/bin/pip" ] || python3 -m venv "$tools"
# Run every time so that a changed pin takes effect; a satisfied one costs a second.
"$tools/bin/pip" install --quiet --disable-pip-version-check "maturin>=1.9,<2" "ziglang==0.17.1"
mkdir -p "$out"
cd "$root/python"
PATH="$tools/bin:$PATH" maturin build --release --zig --compatibility manylinux2014 --strip \
    --out "$out"
