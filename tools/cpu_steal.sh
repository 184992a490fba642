#!/usr/bin/env bash
# Makes this machine behave like an over-committed virtual one, to rehearse
# the real-time tests where CI may run them: on every CPU a SCHED_FIFO
# process takes the CPU for BUSY_MIN-BUSY_MAX ms, then leaves it for
# IDLE_MIN-IDLE_MAX ms (fixed seeds), as a hypervisor's steal does. Ordinary
# threads on that CPU wait meanwhile, so timed waits wake late:
#   sudo bash tools/cpu_steal.sh [SECONDS] [BUSY_MIN BUSY_MAX IDLE_MIN IDLE_MAX]
# Default: 600 s, busy 5-20 ms, idle 50-150 ms. Run a test beside it, e.g.
#   sudo bash tools/cpu_steal.sh 300 & ctest --test-dir build -R test_qos_events
# and tools/timer_check.sh shows what it does to sleeps (on the 2-core Xeon
# VM with the defaults, two runs: 8.1 ms sleeps took 9.1 and 20.7 ms on
# average, 16 and 252 ms at worst; it varies with how the bursts fall).
# Needs root (SCHED_FIFO); stops on SIGINT/SIGTERM or after SECONDS.
set -euo pipefail
seconds=${1:-600}
busy_min=${2:-5} busy_max=${3:-20} idle_min=${4:-50} idle_max=${5:-150}
exec python3 - "$seconds" "$busy_min" "$busy_max" "$idle_min" "$idle_max" <<'PY'
import os, random, signal, sys, time

seconds, busy_min, busy_max, idle_min, idle_max = (float(a) for a in sys.argv[1:6])
children = []
for cpu in sorted(os.sched_getaffinity(0)):
    pid = os.fork()
    if pid == 0:
        os.sched_setaffinity(0, {cpu})
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(50))
        rng = random.Random(cpu)
        while True:
            until = time.monotonic() + rng.uniform(busy_min, busy_max) / 1000.0
            while time.monotonic() < until:
                pass
            time.sleep(rng.uniform(idle_min, idle_max) / 1000.0)
    children.append(pid)


def stop(*_):
    for pid in children:
        os.kill(pid, signal.SIGKILL)
    sys.exit(0)


signal.signal(signal.SIGTERM, stop)
signal.signal(signal.SIGINT, stop)
print(f"cpu_steal: {len(children)} CPUs, busy {busy_min:g}-{busy_max:g} ms, "
      f"idle {idle_min:g}-{idle_max:g} ms, for {seconds:g} s", file=sys.stderr)
time.sleep(seconds)
stop()
PY
