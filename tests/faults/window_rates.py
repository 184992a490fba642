#!/usr/bin/env python3
"""A station's stream rates in labelled windows of one run, against its calm windows.

    window_rates.py [--real-time STREAM:HZ:MIN] PROBE_FILE WINDOWS_FILE CHECK...

PROBE_FILE is fault_probe's (--states): P (DevicePose), C (ForceCommand) and
S (DeformationState) lines, each ending in its writer's header: the writer's
count of writes (seq) and when it wrote the sample (source wall ns). A
stream's rate in a window is how far its writer's count moved across it,
read from the samples the probe got on either side of each edge: the
writer's own rate, which a probe that lags or drops samples does not
change.
Samples with the intruder's writer_id (hostile_peer's 0xbad) are not
counted. WINDOWS_FILE has one window a line, "<label> <start wall ns> <end
wall ns>"; the label "calm" is the reference. 100 ms at each edge of a
window are left out.

A CHECK is LABEL:STREAM:MIN[:pooled], STREAM one of gateway, haptic, fem:
that stream's rate in LABEL's windows must be at least MIN times its calm
rate: each window's rate against the mean of the calm windows just before
and after it, the median of those ratios over the label's windows (the
script's phases move the rates slowly, other work on the machine in bursts).
With ":pooled" the ratio is of all LABEL windows' samples per second to all
calm windows': for a stream that stalls on its own for a good part of a
window (a FEM step of a few hundred ms, a divergence reset), where one
window's rate says more about the stall than about LABEL; a stream that
LABEL stalls still falls to 0 either way.

With --real-time, the checks are judged only if the machine kept the
station in real time: STREAM's rate over the calm windows at least MIN x
HZ (the gateway's 1 kHz servo, say). A machine whose host steals its CPU
(a 2-core VM where 1 ms sleeps took 15 ms on average and the gateway's
SCHED_FIFO loop managed 420 ticks a second) moves every rate by tens of
per cent from one second to the next, so a window's rate says more about
the steal than about the window's label; the table is printed and the
checks are shown as not judged.
Prints the table (every label, every stream) and exits 1 if a judged check
fails. The bounds are the callers' (hostile_test.sh, overload_test.sh).
"""
import bisect
import sys
from collections import defaultdict

INTRUDER = 0xBAD
EDGE_NS = 100_000_000
STREAMS = {"P": "gateway", "C": "haptic", "S": "fem"}
NAMES = {"gateway": "gateway DevicePose", "haptic": "haptic ForceCommand",
         "fem": "FEM DeformationState"}


def main(argv: list) -> int:
    real_time = None
    if len(argv) > 2 and argv[1] == "--real-time":
        parts = argv[2].split(":")
        if len(parts) != 3 or parts[0] not in NAMES:
            print(f"window_rates: bad --real-time '{argv[2]}' (STREAM:HZ:MIN)", file=sys.stderr)
            return 2
        real_time = (parts[0], float(parts[1]), float(parts[2]))
        argv = argv[:1] + argv[3:]
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
    # Each writer's (source time, seq) as the probe saw them.
    progress = defaultdict(list)
    with open(argv[1], encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            parts = line.split()
            if not parts or parts[0] not in STREAMS:
                continue
            try:
                writer, seq, source_ns = int(parts[2]), int(parts[-2]), int(parts[-1])
            except (ValueError, IndexError):
                print(f"window_rates: {argv[1]}:{number}: not a fault_probe line", file=sys.stderr)
                return 2
            if writer != INTRUDER:
                progress[(STREAMS[parts[0]], writer)].append((source_ns, seq))
    for samples in progress.values():
        samples.sort()

    def count_at(samples, t):
        # The writer's count at t: that of its last sample written before t.
        i = bisect.bisect_left(samples, (t, -1))
        return samples[i - 1][1] if i > 0 else samples[0][1] - 1

    # Writes per window, each window on its own, summed over a stream's writers.
    counts = defaultdict(int)
    for (stream, _), samples in progress.items():
        for label, spans in windows.items():
            for i, (a, b) in enumerate(spans):
                counts[(label, i, stream)] += max(0, count_at(samples, b) - count_at(samples, a))
    seconds = {label: sum(b - a for a, b in spans) * 1e-9 for label, spans in windows.items()}

    def rate_of(label, i, s):
        a, b = windows[label][i]
        return counts[(label, i, s)] / ((b - a) * 1e-9)

    def median(values):
        v = sorted(values)
        n = len(v)
        return 0.0 if n == 0 else v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])

    calm = windows["calm"]

    def ratio(label, s):
        # Each window against the calm windows just before and after it (the
        # script's phases move the rates slowly; a window is compared with
        # its neighbours), then the median over the label's windows.
        ratios = []
        for i, (a, b) in enumerate(windows[label]):
            before = [j for j, (ca, cb) in enumerate(calm) if cb <= a]
            after = [j for j, (ca, cb) in enumerate(calm) if ca >= b]
            near = ([max(before, key=lambda j: calm[j][1])] if before else []) + \
                   ([min(after, key=lambda j: calm[j][0])] if after else [])
            reference = sum(rate_of("calm", j, s) for j in near) / len(near) if near else 0.0
            if reference > 0:
                ratios.append(rate_of(label, i, s) / reference)
        return median(ratios)

    def pooled(label, s):
        total = sum(counts[(label, i, s)] for i in range(len(windows[label]))) / seconds[label]
        reference = sum(counts[("calm", i, s)] for i in range(len(calm))) / seconds["calm"]
        return total / reference if reference > 0 else 0.0

    checks = {}
    for c in argv[3:]:
        parts = c.split(":")
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "pooled"):
            print(f"window_rates: bad check '{c}' (LABEL:STREAM:MIN[:pooled])", file=sys.stderr)
            return 2
        checks[(parts[0], parts[1])] = (float(parts[2]), len(parts) == 4)
    labels = ["calm"] + sorted(l for l in windows if l != "calm")
    print("| window | seconds | " + " | ".join(f"{NAMES[s]} per s (x its calm neighbours)"
                                              for s in NAMES) + " |")
    print("| --- | ---: |" + " ---: |" * len(NAMES))
    for label in labels:
        cells = []
        for s in NAMES:
            mean = sum(counts[(label, i, s)] for i in range(len(windows[label]))) / seconds[label]
            cells.append(f"{mean:.1f}" if label == "calm" else f"{mean:.1f} ({ratio(label, s):.3f})")
        print(f"| {label} | {seconds[label]:.1f} | " + " | ".join(cells) + " |")
    judged = True
    if real_time is not None:
        stream, hz, fraction = real_time
        held = sum(counts[("calm", i, stream)] for i in range(len(calm))) / seconds["calm"]
        judged = held >= fraction * hz
        print(f"  {NAMES[stream]} in the calm windows {held:.1f} per s of its {hz:.0f}: "
              + ("the machine kept the station in real time" if judged else
                 f"below {fraction:.2f} of it, the machine did not keep the station in real "
                 "time; the checks below are not judged"))
    status = 0
    for (label, s), (bound, is_pooled) in checks.items():
        if label not in windows:
            r = 0.0
        else:
            r = pooled(label, s) if is_pooled else ratio(label, s)
        ok = r >= bound
        status |= 0 if ok or not judged else 1
        how = "of its calm rate (all windows pooled" if is_pooled else \
            "of its calm neighbours (median"
        verdict = ("ok  " if ok else "FAIL") if judged else "open"
        print(f"  {verdict}  {NAMES[s]} in '{label}' windows at {r:.3f} "
              f"{how}; bound {bound:.2f})")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv))
