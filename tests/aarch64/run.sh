#!/usr/bin/env bash
# The golden-frame tests (tests/golden.rs) cross compiled for aarch64 and run under qemu-user:
# the frames must match the same PNGs bit for bit on another architecture.
#
# Installs what is missing (qemu-user, the aarch64 C/C++ cross compilers -- meshopt, a
# dev-dependency, builds C++ -- and the Rust target), then runs
# `cargo test --test golden --target aarch64-unknown-linux-gnu`. Extra arguments go to
# `cargo test`, e.g. `tests/aarch64/run.sh -- --nocapture`.
set -euo pipefail
cd "$(dirname "$0")/../.."

TARGET=aarch64-unknown-linux-gnu

sudo_if_needed() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

missing=()
command -v qemu-aarch64 >/dev/null || missing+=(qemu-user)
command -v aarch64-linux-gnu-gcc >/dev/null || missing+=(gcc-aarch64-linux-gnu)
command -v aarch64-linux-gnu-g++ >/dev/null || missing+=(g++-aarch64-linux-gnu)
# The C library to link against: a recommendation of the cross compiler, so a compiler installed
# without recommendations (or by another script) can be there without it.
[ -e /usr/aarch64-linux-gnu/lib/Scrt1.o ] || missing+=(libc6-dev-arm64-cross)
if [ "${#missing[@]}" -gt 0 ]; then
    echo "installing ${missing[*]}"
    sudo_if_needed apt-get update
    sudo_if_needed env DEBIAN_FRONTEND=noninteractive apt-get install -y "${missing[@]}"
fi
rustup target add "$TARGET"

export CC_aarch64_unknown_linux_gnu=aarch64-linux-gnu-gcc
export CXX_aarch64_unknown_linux_gnu=aarch64-linux-gnu-g++
export AR_aarch64_unknown_linux_gnu=aarch64-linux-gnu-ar
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu"

cargo test --test golden --target "$TARGET" "$@"
