#!/usr/bin/env python3
"""2-thread speed-up of the DEM engine under several builds / wait policies, side by side.

Runs `bench_dem_packing STEPS 2 1` (1 then 2 threads, N = 13,824 and 54,872) for every
configuration, in rotating order, ROUNDS times, and prints the median speed-up of each. While
each run goes, it reads /proc/stat and the run's own CPU time, so that it can tell how much of
the machine other processes took (runs where they used more than --clean cores are reported
apart). --hog N keeps N busy-loop processes running throughout: the "another job holds a core"
case, where spinning threads hurt.

  tools/bench_thread_scaling.py [--rounds R] [--steps S] [--hog N]
      LABEL=BINARY[:VAR=VALUE,VAR=VALUE] ...
e.g.
  tools/bench_thread_scaling.py new=build/bench/bench_dem_packing \
      new-passive=build/bench/bench_dem_packing:OMP_WAIT_POLICY=PASSIVE \
      old=../magbrush-old/build/bench/bench_dem_packing
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import time


def cpu_busy_seconds():
    """System-wide busy CPU time [s] from /proc/stat (all cores)."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    idle = fields[3] + fields[4]
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")


def run_once(binary, env_extra, steps):
    env = dict(os.environ)
    env.update(env_extra)
    before_self = resource.getrusage(resource.RUSAGE_CHILDREN)
    busy0, t0 = cpu_busy_seconds(), time.time()
    out = subprocess.run([binary, str(steps), "2", "1"], env=env, capture_output=True, text=True, check=True).stdout
    busy1, t1 = cpu_busy_seconds(), time.time()
    after_self = resource.getrusage(resource.RUSAGE_CHILDREN)
    own = (after_self.ru_utime - before_self.ru_utime) + (after_self.ru_stime - before_self.ru_stime)
    others = max(0.0, (busy1 - busy0) - own) / (t1 - t0)  # cores used by other processes
    rates = {}
    for line in out.splitlines():
        m = re.match(r"\s*(\d+)\s+([12])\s+([0-9.e+]+)\s+", line)
        if m:
            rates[(int(m.group(1)), int(m.group(2)))] = float(m.group(3))
    speedups = {n: rates[(n, 2)] / rates[(n, 1)] for (n, t) in rates if t == 1 and (n, 2) in rates}
    return speedups, {n: rates[(n, 1)] for (n, t) in rates if t == 1}, others


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--hog", type=int, default=0, help="busy-loop processes to run alongside")
    ap.add_argument("--session-nice", type=int, default=None,
                    help="run in a new session whose scheduling group has this nice value (root; e.g. -15): "
                         "on a shared machine, other sessions' jobs then take little CPU from the benchmark")
    ap.add_argument("--clean", type=float, default=0.15, help="max cores used by others for a 'clean' run")
    ap.add_argument("configs", nargs="+")
    a = ap.parse_args()
    if a.session_nice is not None and os.environ.get("MAGBRUSH_BENCH_SESSION") is None:
        # Linux groups the CPU share by session (autogroup): nice only counts inside one.
        os.environ["MAGBRUSH_BENCH_SESSION"] = "1"
        os.execvp("setsid", ["setsid", sys.executable] + sys.argv)
    if a.session_nice is not None:
        with open("/proc/self/autogroup", "w") as f:
            f.write(str(a.session_nice))
    configs = []
    for c in a.configs:
        label, rest = c.split("=", 1)
        binary, _, envs = rest.partition(":")
        env = dict(kv.split("=", 1) for kv in envs.split(",") if kv)
        configs.append((label, binary, env))
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(a.hog)]
    results = {label: [] for label, _, _ in configs}
    try:
        for r in range(a.rounds):
            order = configs[r % len(configs):] + configs[:r % len(configs)]
            for label, binary, env in order:
                sp, one, others = run_once(binary, env, a.steps)
                results[label].append((sp, one, others))
                print(f"round {r + 1} {label:>14}: " + "  ".join(f"N={n} x{v:.2f}" for n, v in sorted(sp.items())) +
                      f"   others {others:.2f} cores", flush=True)
    finally:
        for h in hogs:
            h.kill()
    print(f"\nmedian 2-thread speed-up over {a.rounds} rounds ({a.steps} steps, {a.hog} busy-loop jobs alongside);"
          f" 'clean' = runs where other processes used <= {a.clean} cores")
    print(f"{'config':>14} {'N':>7} {'all runs: median (min-max)':>30} {'clean runs: median (n)':>24} {'1-thread p-steps/s':>20}")
    for label, _, _ in configs:
        runs = results[label]
        for n in sorted(runs[0][0]):
            allv = [s[n] for s, _, _ in runs]
            clean = [s[n] for s, _, o in runs if o <= a.clean + a.hog]
            one = statistics.median(o1[n] for _, o1, _ in runs)
            cl = f"{statistics.median(clean):.2f} ({len(clean)})" if clean else "- (0)"
            print(f"{label:>14} {n:>7} {statistics.median(allv):>10.2f} ({min(allv):.2f}-{max(allv):.2f}){'':>8} {cl:>24} {one:>20.3g}")


if __name__ == "__main__":
    main()
