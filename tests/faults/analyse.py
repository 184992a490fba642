#!/usr/bin/env python3
"""Reads fault_test.sh's files (cases.txt, probe-N.txt) and prints the table
service x signal: detected after, force on the device (peak, largest step per
servo tick), zero after, recovered after, run completed. Exit status 1 if a
case breaks a rule:

- every case: the largest step of the force the device rendered, per servo
  tick, from the fault's handling until the haptic service renders the
  tissue again (the first FORCE_RENDERED command after the service is back:
  the ramp, the hold and the resume slew), is at most 0.1 N (plus 1e-6 for
  the wire's rounding). The handling starts when the loss is seen (FEM,
  haptic service) or when the gateway is back (restart, SIGCONT); before
  that the device renders what the haptic service computes as if nothing
  happened, ordinary rendering, whose steps are reported, not judged (its
  own column), as are the logger's and the control's windows (until 1 s
  after the fault);
- FEM: the loss is seen (a ForceCommand with reason FORCE_TISSUE_LOST)
  within DETECT_FEM_MS of the fault; the force is zero within 200 ms of
  that; rendering resumes (FORCE_RENDERED) after the FEM is back;
- haptic: the gateway stops rendering it (its silence rule: the device
  leaves ENABLED, RAMPING_DOWN) and the force is zero within 200 ms of
  that; the tissue is rendered again once the haptic service is back;
- gateway: the tissue is rendered again on the new or continued gateway;
- timing and a starved machine: the three rules in milliseconds (detected
  within, zero within, rendered again, which needs the FEM kept for a whole
  resume slew) hold on a machine that runs the station in real time. A
  case in which the station's own real-time rules fired before the fault
  (the haptic service lost the FEM, or the probe saw the gateway's poses
  stop for longer than the haptic service's 50 ms silence rule) ran on a
  machine that did not: there they are reported, not judged, and what is
  judged instead is that the restarted or continued service is back in the
  loop at all (a command with the tissue resuming or rendered after it is
  back). The force steps and the runs' completion are judged everywhere;
- logger: nothing changes: no ramp-down, and no FEM loss unless the machine
  lost the FEM before the fault too (a starved machine does: counted);
- every case: every service runs at its end and the gateway exits cleanly.
Times are wall-clock (the probe stamps each sample as it arrives).
"""
import os
import sys

# The probe prints force components to 1e-6 N: their differences' norm
# carries that rounding.
STEP_LIMIT_N = 0.1 + 1e-5
# The passivity controller's damper may act while the hand moves, whatever
# is commanded: "zero" leaves it a few hundredths of a newton.
ZERO_N = 0.05
ZERO_WITHIN_MS = 200.0
# The FEM steps every 5 ms; the haptic service calls it lost after 50 ms
# without a state, and notices on its next tick. A loaded machine adds its
# scheduling delay.
DETECT_FEM_MS = 150.0
SETTLE_S = 1.0
# The haptic service holds (and the gateway ramps down) after 50 ms without
# a DevicePose: a longer gap between poses before the fault means the
# machine did not run the station in real time.
POSE_SILENCE_MS = 50.0

FORCE_RENDERED, FORCE_RESUMING, FORCE_TISSUE_LOST, FORCE_DEVICE_NOT_ENABLED = range(4)
DISABLED, ENGAGING, ENABLED, RAMPING_DOWN, FAULT = range(5)


def load(path):
    poses, commands = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if p[0] == "P":
                poses.append((int(p[1]), int(p[2]), int(p[3]), int(p[4]), float(p[5]),
                              (float(p[6]), float(p[7]), float(p[8]))))
            elif p[0] == "C":
                commands.append((int(p[1]), int(p[2]), int(p[3]), int(p[4]), float(p[5])))
    poses.sort(key=lambda x: (x[1], x[2]))  # by gateway, then servo tick
    commands.sort()
    return poses, commands


def largest_step(poses, t0, t1):
    """Largest |F(k+1) - F(k)| over consecutive servo ticks of one gateway
    whose samples arrived within [t0, t1]."""
    worst, worst_at = 0.0, None
    prev = None
    for p in poses:
        if not (t0 <= p[0] <= t1):
            prev = None
            continue
        if prev is not None and prev[1] == p[1] and p[2] == prev[2] + 1:
            d = sum((a - b) ** 2 for a, b in zip(p[5], prev[5])) ** 0.5
            if d > worst:
                worst, worst_at = d, p[0]
        prev = p
    return worst, worst_at


def ms(ns):
    return ns / 1e6


def main(folder):
    rows, failures, open_items = [], [], []
    with open(os.path.join(folder, "cases.txt")) as f:
        cases = [line.split() for line in f if line.strip()]
    for c in cases:
        n, service, signal = c[0], c[1], c[2]
        start, fault, back, ready, end, completed = (int(x) for x in c[3:9])
        poses, commands = load(os.path.join(folder, f"probe-{n}.txt"))
        by_time = sorted(poses)
        name = f"{service} {signal}"
        problems, notes = [], []
        detected = zero = recovered = None
        # Recovered: the first command rendering the tissue again (its
        # resume slew over) after the service is back.
        def rendered_after(t):
            r = [c for c in commands if c[0] > t and c[3] == FORCE_RENDERED]
            return r[0][0] if r else None

        if service == "fem":
            lost = [c for c in commands if c[0] >= fault and c[3] == FORCE_TISSUE_LOST]
            if lost:
                detected = lost[0][0]
                recovered = rendered_after(max(detected, back))
        elif service == "haptic":
            # The device leaves ENABLED (RAMPING_DOWN); one that was not
            # rendering at the fault has nothing to ramp down.
            ramp = [p for p in by_time if p[0] >= fault and p[3] != ENABLED]
            if ramp:
                detected = ramp[0][0]
                recovered = rendered_after(max(detected, back))
        elif service == "gateway":
            recovered = rendered_after(back)
        # Background: FEM losses (episodes) the haptic service saw before the
        # fault, in this case: a starved machine loses the FEM now and then.
        def losses(t0, t1):
            n, was = 0, False
            for c in commands:
                if t0 <= c[0] <= t1:
                    lost_now = c[3] == FORCE_TISSUE_LOST
                    n += lost_now and not was
                    was = lost_now
            return n
        background = losses(start, fault)
        # The longest wait between two poses the probe saw before the fault
        # (after the first second: discovery and the engage ramp).
        warm = [p[0] for p in by_time if start + 1e9 <= p[0] <= fault]
        pose_gap_ms = max((ms(b - a) for a, b in zip(warm, warm[1:])), default=0.0)
        starved = background > 0 or pose_gap_ms > POSE_SILENCE_MS
        starved_why = (f"the machine: {background} FEM losses, poses {pose_gap_ms:.0f} ms apart "
                       "before the fault")
        # Back in the loop: the tissue resuming or rendered after the service is back.
        resumed = [c for c in commands
                   if c[0] > back and c[3] in (FORCE_RENDERED, FORCE_RESUMING)]
        if detected is not None:
            z = [p for p in by_time if p[0] >= detected and p[4] <= ZERO_N]
            zero = z[0][0] if z else None
        # The fault's window: from the fault until the tissue is rendered
        # again (the logger's: until 1 s after it is back).
        window_end = recovered if recovered else end
        if service in ("logger", "none"):
            window_end = back + int(SETTLE_S * 1e9)
        # Fault handling starts where the service can act: the loss seen, or
        # the gateway back. Before it, ordinary rendering.
        handling = detected if detected is not None else (back if service == "gateway" else fault)
        step, step_at = largest_step(poses, handling, min(window_end, end))
        unhandled, _ = largest_step(poses, fault, handling)
        before, _ = largest_step(poses, start, fault)
        peak = max((p[4] for p in by_time if fault <= p[0] <= min(window_end, end)), default=0.0)
        at_fault = [p for p in by_time if p[0] <= fault]
        force_at_fault = at_fault[-1][4] if at_fault else 0.0

        # (The logger's and the control's windows hold ordinary rendering
        # only: its steps are the contact model's, reported, not judged.)
        if service not in ("logger", "none") and step > STEP_LIMIT_N:
            problems.append(f"force step {step:.3f} N > 0.1 N at {ms(step_at - fault):.0f} ms "
                            "after the fault")
        if service in ("fem", "haptic"):
            if detected is None:
                problems.append("loss never seen")
            elif service == "fem" and ms(detected - fault) > DETECT_FEM_MS:
                if starved:
                    notes.append(f"loss seen after {ms(detected - fault):.0f} ms "
                                 f"(open: {starved_why})")
                else:
                    problems.append(f"loss seen after {ms(detected - fault):.0f} ms")
        if service in ("fem", "haptic"):
            if detected is not None and (zero is None or ms(zero - detected) > ZERO_WITHIN_MS):
                # A FEM already being lost before the fault in this case
                # (ramps and resumes interleaving on a starved machine; the
                # haptic force chattering, and the gateway's passivity
                # damper holding a few tenths of a newton on the moving
                # hand for a while after the command is zero) is the FEM's
                # rate, not this fault's handling: reported as open.
                if starved:
                    notes.append(f"force not zero within 200 ms (open: {starved_why})")
                else:
                    problems.append("force not zero within 200 ms of the detection")
        if service in ("fem", "haptic", "gateway") and recovered is None:
            if starved and resumed:
                notes.append(f"back in the loop after {ms(resumed[0][0] - back):.0f} ms, never "
                             f"rendered again (open: {starved_why})")
            elif starved:
                problems.append("never back in the loop")
            elif signal == "STOP":
                # Known open: after a 1 s stop a FEM that cannot keep its rate
                # under the blade is lost again and again, so no slew ends
                # (docs/design/faults.md, open questions). Reported, not judged,
                # until the FEM holds its rate; a recovery here says so.
                notes.append("never recovered (open: the FEM's rate)")
            else:
                problems.append("never recovered")
        elif signal == "STOP" and service in ("fem", "haptic", "gateway"):
            notes.append("recovered")
        if service == "logger":
            # Nothing may change. Reported beside the control case (the same
            # script with no fault, none:NONE), not judged: the control
            # loses the FEM in this window as often (docs/design/faults.md).
            after = losses(fault, end)
            if after > 0 and background == 0:
                notes.append(f"the tissue was lost {after} times, never before the fault "
                             "(compare the control case)")
            if any(p[0] >= fault and p[3] == RAMPING_DOWN for p in by_time):
                notes.append("the device ramped down (compare the control case)")
        if service == "none":
            notes.append(f"control: the tissue was lost {losses(fault, end)} times after the "
                         "fault's moment, with no fault")
        if completed != 1:
            problems.append("run did not complete")
        fmt = lambda t, ref: "-" if t is None else f"{ms(t - ref):.0f}"
        rows.append((name, str(background), f"{force_at_fault:.2f}", fmt(detected, fault),
                     fmt(zero, detected) if detected else "-", f"{peak:.2f}", f"{step:.3f}",
                     f"{unhandled:.3f}", f"{before:.3f}", fmt(recovered, back), "yes" if completed else "NO",
                     "; ".join(problems) if problems else "; ".join(["ok"] + notes)))
        failures += [f"{name}: {p}" for p in problems]
        open_items += [f"{name}: {n}" for n in notes if "(open:" in n]
    print("| service signal | FEM losses before the fault | force at fault N | detected after ms "
          "| zero after detection ms | peak N (fault to recovered) "
          "| largest step N/tick (handling to recovered) "
          "| largest step N/tick (fault to handling, ordinary rendering) "
          "| largest step N/tick (before the fault) "
          "| recovered after ms (from restart/SIGCONT) | run completed | verdict |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    if open_items:
        print("\nfault_test: open (reported, not judged):\n" + "\n".join("- " + f for f in open_items))
    if failures:
        print("\nfault_test: FAILED:\n" + "\n".join("- " + f for f in failures))
        return 1
    print("\nfault_test: every case within its rules")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
