#!/usr/bin/env python3
"""Callgrind's instruction counts of one function, attributed to that function's own source lines
through inlining.

Callgrind charges an inlined instruction to the innermost source line (a line of `margin.rs` or
of `core::slice`), so a function that inlines most of its callees, as the cut's walk does, shows
as a long tail of small lines in other files. This reads a profile made with
`--dump-instr=yes`, asks `addr2line -i` for each instruction's chain of inlined frames, and
charges it to the outermost frame: the line of the function itself that the instruction serves.

    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=cg.out \\
        --toggle-collect='orbit_adapt::adapt' target/release/examples/orbit_adapt 1 0 1 on
    benches/profile/outer_lines.py cg.out target/release/examples/orbit_adapt '::evaluate' 400

Arguments: the profile, the binary (built with line tables, e.g.
`CARGO_PROFILE_RELEASE_DEBUG=line-tables-only`), a substring of the function's name, and
optionally a divisor (frames), how many lines to print (40), and a function inlined into it
(`force_split_at`) whose own lines to charge instead (the rest shows as `other`). Prints
instructions per divisor, the share, and the source line.
"""

import collections
import re
import subprocess
import sys


def costs(path, name):
    """Instruction address -> cost, for the instructions of functions whose name holds `name`."""
    names = {}
    out = collections.Counter()
    current = None
    last = 0
    after_call = False
    position = re.compile(r"^(0x[0-9a-f]+|\+\d+|-\d+|\*)(?:\s+\S+)?\s+(\d+)$")
    with open(path) as f:
        for line in f:
            line = line.rstrip("\n")
            if line.startswith(("fn=", "cfn=")):
                # A name is given once, where its id first appears, which may be a call's.
                m = re.match(r"c?fn=\((\d+)\)(?: (.*))?", line)
                if m:
                    if m.group(2):
                        names[m.group(1)] = m.group(2)
                    if line.startswith("fn="):
                        current = names.get(m.group(1), "")
                continue
            if line.startswith("calls="):
                # The next cost line is the call's inclusive cost, not this function's own.
                after_call = True
                continue
            m = position.match(line)
            if not m:
                continue
            a = m.group(1)
            if a.startswith("0x"):
                address = int(a, 16)
            elif a == "*":
                address = last
            elif a.startswith("+"):
                address = last + int(a[1:])
            else:
                address = last - int(a[1:])
            last = address
            if after_call:
                after_call = False
                continue
            if current and name in current:
                out[address] += int(m.group(2))
    return out


def outermost(binary, addresses, within=None):
    """Address -> the outermost `file:line` of its inlining chain, or with `within` the line of
    the outermost frame whose function's name holds it (instructions outside it: `other`)."""
    query = "\n".join(f"0x{a:x}" for a in addresses)
    text = subprocess.run(
        ["addr2line", "-e", binary, "-i", "-f", "-C", "-a"],
        input=query,
        capture_output=True,
        text=True,
    ).stdout
    out = {}
    address = None
    function = None
    for line in text.splitlines():
        if line.startswith("0x"):
            address = int(line, 16)
            function = None
            if within is not None:
                out[address] = "other:?"
        elif address is not None and function is None:
            function = line
        elif address is not None:
            if within is None or within in function:
                out[address] = line.split(" ")[0]
            function = None
    return out


def main():
    if len(sys.argv) < 4:
        print(__doc__)
        sys.exit(2)
    path, binary, name = sys.argv[1:4]
    divisor = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
    shown = int(sys.argv[5]) if len(sys.argv) > 5 else 40
    within = sys.argv[6] if len(sys.argv) > 6 else None
    cost = costs(path, name)
    lines = collections.Counter()
    for address, where in outermost(binary, sorted(cost), within).items():
        lines[where] += cost[address]
    total = sum(cost.values())
    print(f"{total / divisor:.0f} instructions per divisor in functions matching {name!r}")
    sources = {}
    for where, c in lines.most_common(shown):
        file, _, number = where.rpartition(":")
        text = ""
        if number.isdigit():
            try:
                text = sources.setdefault(file, open(file).read().split("\n"))[int(number) - 1]
            except (OSError, IndexError):
                text = ""
        print(f"{c / divisor:9.0f} {100 * c / max(total, 1):5.1f}%  {file.split('/')[-1]}:{number}  {text.strip()[:90]}")


if __name__ == "__main__":
    main()
