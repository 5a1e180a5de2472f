#!/usr/bin/env bash
# A short fuzz run of every target from its seeds, for CI: the targets must build, and a fixed
# number of runs from a fixed seed must find nothing. Built coverage-guided as `cargo fuzz` builds
# them but without a sanitizer, so it needs neither cargo-fuzz nor a nightly toolchain, and with
# overflow checks and debug assertions, so arithmetic that wraps is a finding too. A build's runs
# repeat themselves from run to run, but for the `mesh` target's, whose coverage also follows the
# random hashing of the repair's hash maps (looked up, never iterated: no mesh depends on it).
#
#   fuzz/smoke.sh                  # about a minute to build, two to run
#   RUNS_SCALE=10 fuzz/smoke.sh    # ten times the runs
set -euo pipefail
cd "$(dirname "$0")"
export CARGO_TARGET_DIR=target/smoke
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares -Cllvm-args=-sanitizer-coverage-stack-depth \
--cfg fuzzing -Cdebug-assertions -Coverflow-checks"
# A target of its own, so that the flags reach the targets but not the build scripts.
host=$(rustc -vV | sed -n 's/^host: //p')
cargo build --release --bins --locked --target "$host"
scale=${RUNS_SCALE:-1}
# libFuzzer from a fixed seed repeats itself only where the code sits at the same addresses
# (its tables of compared values are keyed by them): address randomization off, where allowed.
fixed=()
if setarch "$(uname -m)" -R true 2>/dev/null; then fixed=(setarch "$(uname -m)" -R); fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# target, seed folder, runs
while read -r target seeds runs; do
    mkdir -p "$work/$target"
    start=$SECONDS
    echo "fuzz $target: $((runs * scale)) runs from seeds/$seeds"
    ${fixed[@]+"${fixed[@]}"} target/smoke/"$host"/release/"$target" \
        "$work/$target" "seeds/$seeds" -seed=1 -reload=0 -runs=$((runs * scale)) \
        -artifact_prefix="$work/" 2>"$work/$target.log" || {
        tail -40 "$work/$target.log"
        mkdir -p artifacts
        cp "$work"/crash-* "$work"/oom-* "$work"/timeout-* artifacts/ 2>/dev/null || true
        echo "fuzz $target: a finding (above; the input is in fuzz/artifacts/)" >&2
        exit 1
    }
    echo "  $(grep -o 'DONE .*' "$work/$target.log" | head -1) in $((SECONDS - start)) s"
done <<'LIST'
hierarchy hierarchy 4000000
cut hierarchy 50000
obj obj 1000000
mesh mesh 500000
semiregular semiregular 100000
LIST
