#!/usr/bin/env python3
"""The station's rates with the intruder flooding and resting, interleaved.

    hostile_rates.py PROBE_FILE HOSTILE_LOG

PROBE_FILE is fault_probe's (--states): P (DevicePose), C (ForceCommand) and
S (DeformationState) lines, each with its receive time and the writer_id in
its header. HOSTILE_LOG holds hostile_peer's "hostile: on <ns> <ns>" lines.
The windows between two floods are the calm ones. 100 ms at each edge of a
window are left out. Samples with the intruder's writer_id are not counted.
Prints the table and exits 1 when a service falls below its bound: 99 % of
its calm rate for the gateway's poses and the haptic service's commands,
90 % for the FEM's states (a CPU-bound step: the CPU the receivers spend on the
intruder is partly its own; its rate also moves with the script's phases).
"""
import sys

INTRUDER = 0xBAD
EDGE_NS = 100_000_000
BOUNDS = {"gateway DevicePose": 0.99, "haptic ForceCommand": 0.99, "FEM DeformationState": 0.90}
KINDS = {"P": "gateway DevicePose", "C": "haptic ForceCommand", "S": "FEM DeformationState"}


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    probe, hostile = sys.argv[1], sys.argv[2]
    floods = []
    with open(hostile, encoding="utf-8") as f:
        for line in f:
            parts = line.split()
            if len(parts) == 4 and parts[:2] == ["hostile:", "on"]:
                floods.append((int(parts[2]), int(parts[3])))
    if len(floods) < 2:
        print(f"hostile_rates: {hostile}: fewer than two floods", file=sys.stderr)
        return 1
    calm = [(floods[i][1], floods[i + 1][0]) for i in range(len(floods) - 1)]
    windows = {"flood": [(a + EDGE_NS, b - EDGE_NS) for a, b in floods if b - a > 4 * EDGE_NS],
               "calm": [(a + EDGE_NS, b - EDGE_NS) for a, b in calm if b - a > 4 * EDGE_NS]}
    counts = {(w, k): 0 for w in windows for k in KINDS.values()}
    with open(probe, encoding="utf-8") as f:
        for line in f:
            parts = line.split()
            if not parts or parts[0] not in KINDS or int(parts[2]) == INTRUDER:
                continue
            t = int(parts[1])
            for w, spans in windows.items():
                if any(a <= t < b for a, b in spans):
                    counts[(w, KINDS[parts[0]])] += 1
    seconds = {w: sum(b - a for a, b in spans) * 1e-9 for w, spans in windows.items()}
    print("| stream | calm per s | flood per s | flood / calm | bound | verdict |")
    print("| --- | ---: | ---: | ---: | ---: | --- |")
    status = 0
    for kind, bound in BOUNDS.items():
        calm_rate = counts[("calm", kind)] / seconds["calm"]
        flood_rate = counts[("flood", kind)] / seconds["flood"]
        ratio = flood_rate / calm_rate if calm_rate > 0 else 0.0
        ok = calm_rate > 0 and ratio >= bound
        status |= 0 if ok else 1
        print(f"| {kind} | {calm_rate:.1f} | {flood_rate:.1f} | {ratio:.3f} | {bound:.2f} | "
              f"{'ok' if ok else 'FAIL'} |")
    print(f"({len(windows['flood'])} flood windows, {seconds['flood']:.1f} s; "
          f"{len(windows['calm'])} calm windows, {seconds['calm']:.1f} s)")
    return status


if __name__ == "__main__":
    sys.exit(main())
