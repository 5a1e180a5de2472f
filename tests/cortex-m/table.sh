#!/usr/bin/env bash
# The device integrator's table: RAM and flash of the linked Cortex-M7 firmware, and its
# instruction counts, for 160x120, 320x240 and 480x320 frames at budgets of 1,000, 2,000, 5,000
# and 10,000 triangles (each configuration built and run by run.sh under qemu). Not part of CI:
# twelve firmware links take a few minutes. Prints one markdown row per configuration.
set -euo pipefail
cd "$(dirname "$0")/../.."
echo "| frame | budget | cut | scratch | bins | band buffers (16 rows) | peak stack | RAM in all | flash | adapt instr. (frames 1-7) | draw instr. (frames 1-7) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for size in 160x120 320x240 480x320; do
    for budget in 1000 2000 5000 10000; do
        export VDLOD_FW_WIDTH=${size%x*} VDLOD_FW_HEIGHT=${size#*x} VDLOD_FW_BUDGET=$budget
        log=target/cortex-m/table-$size-$budget.txt
        tests/cortex-m/run.sh >"$log" 2>&1 || { echo "| $size | $budget | run.sh failed: see $log |"; continue; }
        sym() { awk -v s="frames::$1" '$2 ~ s"$" { print $1 }' "$log" | head -1; }
        band=$(( $(sym BAND_COLOR) + $(sym BAND_DEPTH) ))
        stack=$(sed -n 's/^ram: .*stack_peak=\([0-9]*\).*/\1/p' "$log")
        ram=$(sed -n 's/^ram_bytes=\([0-9]*\) flash_bytes=.*/\1/p' "$log")
        flash=$(sed -n 's/^ram_bytes=[0-9]* flash_bytes=\([0-9]*\)/\1/p' "$log")
        range() { grep -E '^cost frame=[1-7] ' "$log" | sed -n "s/.*$1_instructions=\([0-9]*\).*/\1/p" | sort -n | sed -n '1p;$p' | awk '{ printf "%s%.1fM", (NR > 1 ? "-" : ""), $1 / 1e6 }'; }
        echo "| $size | $budget | $(sym CUT) | $(sym SCRATCH) | $(sym BINS) | $band | $stack | $ram | $flash | $(range adapt) | $(range draw) |"
    done
done
