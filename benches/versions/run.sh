#!/usr/bin/env bash
# The runtime cut of this checkout beside the cut of older commits, in one process: each
# version's `vdlod-core` is compiled as its own crate, each builds its own bunny hierarchy, and
# every version adapts the same views of the peer orbit (QRefine, no budget, no geomorphs) in
# blocks of 8 frames, the order rotating, so the machine's slow phases hit them alike. Prints,
# per tolerance, each version's median and mean microseconds and mean triangles, the median of
# the per-frame time ratios against this checkout and the ratio of total times; then the same for the first frame (orbit frame 0
# refined from the base mesh, 20 rounds, each version in turn).
#
#   benches/versions/run.sh COMMIT... [-- TOLERANCES [REVOLUTIONS]]
#   benches/versions/run.sh 14ce786 97fab9c -- 0.25,0.5,1,2,4 2
#
# A commit's cut must have `reset`, `adapt` and `QRefine` as today (any commit since the cut's
# arenas, December 2026); the work folder is `$TMPDIR/vdlod-versions`.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
commits=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do commits+=("$1"); shift; done
[ $# -gt 0 ] && shift
args=("$@")
[ ${#commits[@]} -gt 0 ] || { echo "usage: $0 COMMIT... [-- TOLERANCES [REVOLUTIONS]]" >&2; exit 2; }
work="${TMPDIR:-/tmp}/vdlod-versions"
rm -rf "$work/src" "$work"/core-*
mkdir -p "$work/src"
members='"."'
deps=""
engines=""
names=""
for c in "${commits[@]}"; do
    name="core-$c"
    mkdir -p "$work/tmp-$c"
    git -C "$repo" archive "$c" core | tar x -C "$work/tmp-$c"
    mv "$work/tmp-$c/core" "$work/$name" && rm -rf "$work/tmp-$c"
    sed -i "0,/^name = .*/s//name = \"$name\"/" "$work/$name/Cargo.toml"
    members="$members, \"$name\""
    deps="$deps$name = { path = \"$name\", features = [\"build\"] }"$'\n'
    krate="core_$c"
    if grep -q "fn boxed" "$work/$name/src/cut/"*.rs; then new="$krate::cut::Cut::boxed()"; else new="Box::default()"; fi
    engines="${engines}engine!($krate, $krate::cut::Cut<16384, 32768, 2048>, $new),"$'\n'
    names="$names\"$c\", "
done
cat >"$work/Cargo.toml" <<TOML
[package]
name = "vdlod-versions"
version = "0.1.0"
edition = "2021"

[dependencies]
vdlod-core = { path = "$repo/core", features = ["build"] }
vdlod-demo = { path = "$repo/host-demo" }
$deps
[profile.release]
codegen-units = 1

[workspace]
members = [$members]
[workspace.package]
version = "0.1.0"
edition = "2021"
rust-version = "1.88"
license = "MIT OR Apache-2.0"
[workspace.dependencies]
libm = "0.2"
heapless = "0.9"
TOML
cp "$repo/Cargo.lock" "$work/Cargo.lock"
python3 - "$here/main.rs.in" "$work/src/main.rs" "$engines" "$names" <<'PY'
import sys
src, dst, engines, names = sys.argv[1:5]
open(dst, "w").write(open(src).read().replace("@ENGINES@", engines).replace("@NAMES@", names))
PY
cd "$work" && cargo build --release -q && ./target/release/vdlod-versions "${args[@]}"
