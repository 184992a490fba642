#!/usr/bin/env python3
"""A station's stream rates in labelled windows of one run, against its calm windows.

    window_rates.py PROBE_FILE WINDOWS_FILE CHECK...

PROBE_FILE is fault_probe's (--states): P (DevicePose), C (ForceCommand) and
S (DeformationState) lines, each with its receive time (wall ns) and the
writer_id in its header; samples with the intruder's writer_id
(hostile_peer's 0xbad) are not counted. WINDOWS_FILE has one window a line,
"<label> <start wall ns> <end wall ns>"; the label "calm" is the reference.
100 ms at each edge of a window are left out.

A CHECK is LABEL:STREAM:MIN, STREAM one of gateway, haptic, fem: that
stream's rate in LABEL's windows must be at least MIN times its calm rate.
Prints the table (every label, every stream) and exits 1 if a check fails.
The bounds are the callers' (hostile_test.sh, overload_test.sh).
"""
import sys
from collections import defaultdict

INTRUDER = 0xBAD
EDGE_NS = 100_000_000
STREAMS = {"P": "gateway", "C": "haptic", "S": "fem"}
NAMES = {"gateway": "gateway DevicePose", "haptic": "haptic ForceCommand",
         "fem": "FEM DeformationState"}


def main(argv: list) -> int:
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    windows = defaultdict(list)
    with open(argv[2], encoding="utf-8") as f:
        for line in f:
            parts = line.split()
            if len(parts) == 3 and int(parts[2]) - int(parts[1]) > 4 * EDGE_NS:
                windows[parts[0]].append((int(parts[1]) + EDGE_NS, int(parts[2]) - EDGE_NS))
    if "calm" not in windows:
        print(f"window_rates: {argv[2]}: no calm window", file=sys.stderr)
        return 1
    counts = defaultdict(int)
    with open(argv[1], encoding="utf-8") as f:
        for line in f:
            parts = line.split()
            if not parts or parts[0] not in STREAMS or int(parts[2]) == INTRUDER:
                continue
            t = int(parts[1])
            for label, spans in windows.items():
                if any(a <= t < b for a, b in spans):
                    counts[(label, STREAMS[parts[0]])] += 1
    seconds = {label: sum(b - a for a, b in spans) * 1e-9 for label, spans in windows.items()}
    rate = lambda label, s: counts[(label, s)] / seconds[label]
    checks = {}
    for c in argv[3:]:
        label, stream, bound = c.split(":")
        checks[(label, stream)] = float(bound)
    labels = ["calm"] + sorted(l for l in windows if l != "calm")
    print("| window | seconds | " + " | ".join(f"{NAMES[s]} per s (x calm)" for s in NAMES) + " |")
    print("| --- | ---: |" + " ---: |" * len(NAMES))
    for label in labels:
        cells = []
        for s in NAMES:
            ratio = rate(label, s) / rate("calm", s) if rate("calm", s) > 0 else 0.0
            cells.append(f"{rate(label, s):.1f} ({ratio:.3f})")
        print(f"| {label} | {seconds[label]:.1f} | " + " | ".join(cells) + " |")
    status = 0
    for (label, s), bound in checks.items():
        calm = rate("calm", s)
        ratio = rate(label, s) / calm if label in windows and calm > 0 else 0.0
        ok = ratio >= bound
        status |= 0 if ok else 1
        print(f"  {'ok  ' if ok else 'FAIL'}  {NAMES[s]} in '{label}' windows at {ratio:.3f} "
              f"of its calm rate (bound {bound:.2f})")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
