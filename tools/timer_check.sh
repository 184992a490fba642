#!/usr/bin/env bash
# How late this machine's timed waits wake, before trusting it with real-time
# runs or tests (a 1 kHz service needs a sleep of under a millisecond to wake
# within a fraction of one):
#   bash tools/timer_check.sh [SAMPLES]   (default 50 per length)
# Prints, per sleep length, the mean and worst time actually slept. On an
# ordinary machine they are the asked length plus some 0.1 ms; on an
# over-committed virtual machine tens to hundreds of milliseconds more.
set -euo pipefail
samples="${1:-50}"
python3 - "$samples" <<'PY'
import sys, time
n = int(sys.argv[1])
print("| sleep ms | mean slept ms | worst slept ms |")
print("| ---: | ---: | ---: |")
for asked_ms in (0.1, 1.0, 2.7, 8.1):
    slept = []
    for _ in range(n):
        start = time.monotonic_ns()
        time.sleep(asked_ms / 1000.0)
        slept.append((time.monotonic_ns() - start) / 1e6)
    print(f"| {asked_ms:.1f} | {sum(slept) / n:.2f} | {max(slept):.2f} |")
PY
