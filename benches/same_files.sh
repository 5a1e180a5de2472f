#!/usr/bin/env bash
# Every file the builders write, the same byte for byte as another commit's?
#
#   benches/same_files.sh BASE_REV
#
# Builds `vdlod-demo` at BASE_REV (in a throwaway worktree) and as the working tree stands, then
# has both write the hierarchies of the five fixtures under eight option sets, of the
# Loop-subdivided bunny twice (default and Table 1's `--cost edge --balanced`), and two remeshes,
# and compares each pair with `cmp`. Prints one line per file and exits 1 if any differs. A
# change to the builders that should not change their output (a speed-up, a tidy) is checked
# with this before it lands. About ten minutes on two cores, most of it the two builds.
set -euo pipefail

base=${1:?usage: benches/same_files.sh BASE_REV}
root=$(git rev-parse --show-toplevel)
work=${SAME_FILES_DIR:-/tmp/vdlod-same-files}
mkdir -p "$work"

build() { # build REV_DIR TARGET_DIR
    CARGO_TARGET_DIR="$2" cargo build --quiet --release --manifest-path "$1/Cargo.toml" \
        -p vdlod-demo --bins
}

rm -rf "$work/base"
git -C "$root" worktree add --quiet --detach "$work/base" "$base"
trap 'git -C "$root" worktree remove --force "$work/base"' EXIT
build "$work/base" "$work/base-target"
build "$root" "$work/new-target"
old="$work/base-target/release/vdlod-demo"
new="$work/new-target/release/vdlod-demo"

rm -rf "$work/out" && mkdir -p "$work/out"
"$new" subdivide "$root/fixtures/bunny.obj" --levels 1 -o "$work/out/bunny_loop.obj" >/dev/null

options=("" "--balanced" "--cost edge --balanced" "--cost edge" "--cost color"
    "--bound spheroid" "--bound hoppe" "--placement endpoint")
jobs=()
for mesh in bunny cow elk fandisk head; do
    for i in "${!options[@]}"; do
        jobs+=("$root/fixtures/$mesh.obj|$mesh-$i|${options[$i]}")
    done
done
jobs+=("$work/out/bunny_loop.obj|loop-default|" "$work/out/bunny_loop.obj|loop-table1|--cost edge --balanced")

differ=0
for job in "${jobs[@]}"; do
    IFS='|' read -r mesh name opts <<<"$job"
    for side in old new; do
        # shellcheck disable=SC2086 # the options are words
        "${!side}" build "$mesh" -o "$work/out/$name.$side.vdh" $opts >/dev/null 2>&1
    done
    if cmp -s "$work/out/$name.old.vdh" "$work/out/$name.new.vdh"; then
        echo "same    $name ($opts)"
    else
        echo "DIFFERS $name ($opts)"
        differ=1
    fi
done
for mesh in bunny fandisk; do
    for side in old new; do
        "${!side}" remesh "$root/fixtures/$mesh.obj" -o "$work/out/remesh-$mesh.$side.vdw" >/dev/null 2>&1
    done
    if cmp -s "$work/out/remesh-$mesh.old.vdw" "$work/out/remesh-$mesh.new.vdw"; then
        echo "same    remesh $mesh"
    else
        echo "DIFFERS remesh $mesh"
        differ=1
    fi
done
exit $differ
