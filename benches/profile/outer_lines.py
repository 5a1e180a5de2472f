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

Options, anywhere among the arguments:

- `--minus BASE` subtracts the counts of profile `BASE` (the same binary, e.g. the same flight
  cut short) address by address: what the frames between the two cost, without the first frame
  both share, e.g. `table1_adapt 400 0.4 100 FILE` minus `table1_adapt 400 0.4 0 FILE`, divided
  by 100;
- `--event K` reads the profile's K-th event instead of the first (with `--branch-sim=yes` the
  events are `Ir Bc Bcm Bi Bim`: `--event 2` counts mispredicted conditional branches);
- `--innermost` charges each instruction to the innermost line instead, as callgrind does, but
  within the functions asked for and summed per line across them.
"""

import collections
import re
import subprocess
import sys


def costs(path, name, event=0):
    """Instruction address -> cost of event `event`, for the instructions of functions whose name
    holds `name`."""
    names = {}
    out = collections.Counter()
    current = None
    last = 0
    after_call = False
    # An instruction's address (absolute, relative to the last, or the same), its line (with
    # `--dump-line=yes`, the default), then one count per event (trailing zeros left out).
    position = re.compile(r"^(0x[0-9a-f]+|\+\d+|-\d+|\*)\s+\S+((?:\s+\d+)*)$")
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
            counts = m.group(2).split()
            if current and name in current and event < len(counts):
                out[address] += int(counts[event])
    return out


def outermost(binary, addresses, within=None, innermost=False):
    """Address -> the outermost `file:line` of its inlining chain, or with `within` the line of
    the outermost frame whose function's name holds it (instructions outside it: `other`), or
    with `innermost` the innermost line."""
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
            if innermost:
                out.setdefault(address, line.split(" ")[0])
            elif within is None or within in function:
                out[address] = line.split(" ")[0]
            function = None
    return out


def main():
    args, minus, event, innermost = [], None, 0, False
    argv = iter(sys.argv[1:])
    for a in argv:
        if a == "--minus":
            minus = next(argv, None)
        elif a == "--event":
            event = int(next(argv, "0"))
        elif a == "--innermost":
            innermost = True
        else:
            args.append(a)
    if len(args) < 3:
        print(__doc__)
        sys.exit(2)
    path, binary, name = args[:3]
    divisor = float(args[3]) if len(args) > 3 else 1.0
    shown = int(args[4]) if len(args) > 4 else 40
    within = args[5] if len(args) > 5 else None
    cost = costs(path, name, event)
    if minus is not None:
        cost.subtract(costs(minus, name, event))
    lines = collections.Counter()
    for address, where in outermost(binary, sorted(cost), within, innermost).items():
        lines[where] += cost[address]
    total = sum(cost.values())
    what = "instructions" if event == 0 else f"counts of event {event}"
    print(f"{total / divisor:.0f} {what} per divisor in functions matching {name!r}")
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
