#!/usr/bin/env bash
# vdlod frames on an emulated Cortex-M7 (qemu mps2-an500) against the twin of the same source on
# the host and on aarch64 (qemu-user): builds the bunny hierarchy, the firmware and the twins,
# runs all three, compares the per-frame hashes (exit 1 on any mismatch or missing frame) and
# reports RAM, flash and instruction counts.
#
# Needs rustup and cargo; installs qemu-system-arm, qemu-user and gcc-aarch64-linux-gnu
# (apt-get), the thumbv7em-none-eabihf and aarch64-unknown-linux-gnu targets and the llvm-tools
# component when missing.
set -euo pipefail
cd "$(dirname "$0")/../.."
export CARGO_TERM_COLOR=never

FRAMES=8
TARGET=thumbv7em-none-eabihf
MANIFEST=tests/cortex-m/Cargo.toml
FW_TARGET_DIR=tests/cortex-m/target
ELF="$FW_TARGET_DIR/$TARGET/release/vdlod-firmware"
HOST_BIN="$FW_TARGET_DIR/release/vdlod-firmware"
ARM64=aarch64-unknown-linux-gnu
ARM64_BIN="$FW_TARGET_DIR/$ARM64/release/vdlod-firmware"
OUT=target/cortex-m
mkdir -p "$OUT"

# --- tools ---------------------------------------------------------------------------------
missing=()
command -v qemu-system-arm >/dev/null 2>&1 || missing+=(qemu-system-arm)
command -v qemu-aarch64 >/dev/null 2>&1 || missing+=(qemu-user)
command -v aarch64-linux-gnu-gcc >/dev/null 2>&1 || missing+=(gcc-aarch64-linux-gnu)
# The C library to link against: a recommendation of the cross compiler, so a compiler installed
# without recommendations (or by another script) can be there without it.
[ -e /usr/aarch64-linux-gnu/lib/Scrt1.o ] || missing+=(libc6-dev-arm64-cross)
if [ "${#missing[@]}" -gt 0 ]; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; fi
    $SUDO apt-get update
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi
rustup target add "$TARGET" "$ARM64"
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
rustup component add llvm-tools
HOST_TRIPLE=$(rustc -vV | sed -n 's/^host: //p')
LLVM_BIN="$(rustc --print sysroot)/lib/rustlib/$HOST_TRIPLE/bin"
LLVM_SIZE="$LLVM_BIN/llvm-size"
LLVM_NM="$LLVM_BIN/llvm-nm"

# --- the hierarchy -------------------------------------------------------------------------
# Replaced only when its bytes change, so that an unchanged file does not relink the firmware.
cargo run --release -p vdlod-demo -- build fixtures/bunny.obj -o "$OUT/bunny.vdh.new"
if cmp -s "$OUT/bunny.vdh.new" "$OUT/bunny.vdh"; then
    rm "$OUT/bunny.vdh.new"
else
    mv "$OUT/bunny.vdh.new" "$OUT/bunny.vdh"
fi
export VDLOD_HIERARCHY="$PWD/$OUT/bunny.vdh"

# --- build both ----------------------------------------------------------------------------
# Panic locations name their source files by path: mapped to the repository's root (and cargo's
# home), the firmware, and with it the flash figure, are the same wherever the repository is
# checked out (a path three characters longer had made it 56 bytes longer).
# (Encoded flags, separated by 0x1f, so that a path with spaces stays one flag.)
export CARGO_ENCODED_RUSTFLAGS="--remap-path-prefix=$PWD=.$(printf '\x1f')--remap-path-prefix=${CARGO_HOME:-$HOME/.cargo}=/cargo"
cargo build --release --manifest-path "$MANIFEST" --target-dir "$FW_TARGET_DIR" --target "$TARGET"
cargo build --release --manifest-path "$MANIFEST" --target-dir "$FW_TARGET_DIR"
cargo build --release --manifest-path "$MANIFEST" --target-dir "$FW_TARGET_DIR" --target "$ARM64"

# --- run both ------------------------------------------------------------------------------
status=0
timeout 600 qemu-system-arm -M mps2-an500 -nographic \
    -semihosting-config enable=on,target=native -icount shift=0 \
    -kernel "$ELF" </dev/null >"$OUT/device.txt" || status=$?
host_status=0
"$HOST_BIN" >"$OUT/host.txt" || host_status=$?
arm64_status=0
qemu-aarch64 -L /usr/aarch64-linux-gnu "$ARM64_BIN" >"$OUT/arm64.txt" || arm64_status=$?

echo "== device (qemu mps2-an500, Cortex-M7, exit $status)"
cat "$OUT/device.txt"
echo "== host twin ($HOST_TRIPLE, exit $host_status)"
cat "$OUT/host.txt"
echo "== twin on aarch64 (qemu-user, exit $arm64_status)"
grep -E '^frame=' "$OUT/arm64.txt" || true

# --- compare -------------------------------------------------------------------------------
fail=0
if [ "$status" -ne 0 ]; then echo "FAIL: qemu exited with $status"; fail=1; fi
if [ "$host_status" -ne 0 ]; then echo "FAIL: the host twin exited with $host_status"; fail=1; fi
if [ "$arm64_status" -ne 0 ]; then echo "FAIL: the aarch64 twin exited with $arm64_status"; fail=1; fi
grep -E '^frame=[0-9]+ hash=' "$OUT/device.txt" | tr -d '\r' >"$OUT/device.hashes" || true
grep -E '^frame=[0-9]+ hash=' "$OUT/host.txt" >"$OUT/host.hashes" || true
grep -E '^frame=[0-9]+ hash=' "$OUT/arm64.txt" >"$OUT/arm64.hashes" || true
for f in device host arm64; do
    n=$(wc -l <"$OUT/$f.hashes")
    if [ "$n" -ne "$FRAMES" ]; then
        echo "FAIL: $f printed $n of $FRAMES frame hashes"
        fail=1
    fi
done
if ! diff -u "$OUT/host.hashes" "$OUT/device.hashes"; then
    echo "FAIL: device and host hashes differ"
    fail=1
fi
if ! diff -u "$OUT/host.hashes" "$OUT/arm64.hashes"; then
    echo "FAIL: aarch64 and host hashes differ"
    fail=1
fi

# --- memory --------------------------------------------------------------------------------
# `llvm-size -A`: one "name size address" line per section, sizes in decimal.
section() { "$LLVM_SIZE" -A "$ELF" | awk -v s="$1" '$1 == s { print $2; f = 1 } END { if (!f) print 0 }'; }
vectors=$(section .vector_table)
text=$(section .text)
rodata=$(section .rodata)
data=$(section .data)
bss=$(section .bss)
uninit=$(section .uninit)
stack=$(sed -n 's/^stack_bytes=\([0-9]*\).*/\1/p' "$OUT/device.txt" | tr -d '\r')
hierarchy=$(stat -c %s "$VDLOD_HIERARCHY")
if [ -z "$stack" ]; then
    echo "FAIL: the device printed no stack_bytes"
    stack=0
    fail=1
fi
ram=$((data + bss + uninit + stack))
flash=$((vectors + text + rodata + data))

echo "== memory"
echo "sections vector_table=$vectors text=$text rodata=$rodata data=$data bss=$bss uninit=$uninit"
echo "flash: hierarchy=$hierarchy code_and_constants=$((flash - hierarchy))"
echo "ram: data=$data bss=$bss stack_peak=$stack"
echo "statics of 1 KiB and more (bytes, symbol):"
"$LLVM_NM" -S -C --size-sort --radix=d "$ELF" | awk '
    $3 ~ /^[bBdD]$/ {
        size = $2 + 0
        if (size >= 1024) {
            name = $4; for (i = 5; i <= NF; i++) name = name " " $i
            sub(/::h[0-9a-f]+$/, "", name)
            printf "  %8d  %s\n", size, name
        }
    }'
echo "ram_bytes=$ram flash_bytes=$flash"
echo "goals: ram <= 262144 ($([ "$ram" -le 262144 ] && echo met || echo NOT met)), flash <= 1500000 ($([ "$flash" -le 1500000 ] && echo met || echo NOT met))"

# --- instructions --------------------------------------------------------------------------
echo "== instructions (qemu -icount shift=0, SysTick at 25 MHz: ticks x 40)"
grep -E '^(systick_calibration|parse_instructions|cost )' "$OUT/device.txt" | tr -d '\r' || true

if [ "$fail" -ne 0 ]; then
    echo "cortex-m: FAILED"
    exit 1
fi
echo "cortex-m: OK ($FRAMES frames, hashes identical on the Cortex-M7, $HOST_TRIPLE and aarch64)"
