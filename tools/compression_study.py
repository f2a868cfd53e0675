#!/usr/bin/env python3
"""Kawamoto's brush compression study: every protocol and carrier size, then the plots.

    tools/compression_study [CASE] [--diameters 42 50 60] [--protocols compression field_sweep
        half_speed] [--box 2mm] [--time-scale 1] [--threads N] [--set key=value ...]
        [--output DIR] [--dry-run] [--plot-only]

runs build/bin/magbrush-dem on CASE (default cases/kawamoto_brush_compression.yaml) once per
carrier size and protocol, with --set overrides (the scene itself is defined once, in the case):

  compression  (a)+(c) the case as it stands: field ramp to 130 mT, plate down at 0.1 m/s from
               1.2 mm to 0.4 mm (normal force against brush length), then slid 1.5 mm sideways
               (tangential force at 0.4 mm);
  field_sweep  (b)+(c) plate down to 0.6 mm and held; the field stepped down 130 -> 15 mT with a
               hold at each level (normal force against B at 0.6 mm); back to 130 mT and slid
               1.5 mm (tangential force at 0.6 mm);
  half_speed   (a) at half the plate speed (the quasi-static check), for the largest diameter;
  stepped      (a) at rest (optional): the plate comes down in 0.1 mm steps at 0.1 m/s, each held
               0.5 ms, the force read over the last half of each hold (the brush relaxes when
               the plate stops: this is the equilibrium curve of the paper's manual stage).

Carrier sizes (Kawamoto: equal mass per area): 42 um x 13,700, 50 um x 7,870, 60 um x 4,420
beads, +-10 % spread, on 2 x 2 mm^2. `--box L` runs a smaller periodic square with the counts
scaled by its area (a quick look: --box 0.5mm); `--time-scale s` multiplies every protocol
time (s < 1: faster plate, less quasi-static).

Outputs: <output.directory>/compression_study/ (or --output): runs/<protocol>_<d>um/ (the DEM
outputs, plate_compression.csv, contact maps), protocol.csv (the phase windows the analysis
averages over), then tools/plot_compression.py writes the summary CSVs and PNGs there.
"""
import argparse
import csv
import os
import shlex
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# Kawamoto's carrier sizes: diameter [um] -> bead count on 2 x 2 mm^2.
COUNTS = {42: 13700, 50: 7870, 60: 4420}
PAPER_AREA_MM = 2.0
INSERT_TOP_MM = 0.9      # the case's insertion layer (see its header)
PLATE_START_MM = 1.2     # the case's plate start height
RAMP_MS, HOLD_MS = 0.3, 0.5
FIELD_LEVELS_MT = [130, 100, 70, 50, 35, 25, 15]


def path_set(points):
    """--set value of planes.plate.path from (t_ms, dx_mm, dz_mm) points."""
    items = ", ".join("{time: %.6g ms, displacement: [%.6g mm, 0 mm, %.6g mm]}" % p for p in points)
    return "planes.plate.path=[%s]" % items


def schedule_set(points):
    items = ", ".join("{time: %.6g ms, magnitude: %.6g mT}" % p for p in points)
    return "applied_field.schedule=[%s]" % items


def protocol(name, s):
    """(overrides, duration_ms, phases) of one protocol; s scales every time."""
    ramp = [(0.0, 0.0), (RAMP_MS * s, 130.0)]
    hold = HOLD_MS * s
    if name == "compression":  # the case's own path, restated so that --time-scale applies
        t_down = hold + 8.0 * s
        t_end = t_down + 6.0 * s
        path = [(0, 0, 0), (hold, 0, 0), (t_down, 0, -0.8), (t_end, 1.5, -0.8)]
        phases = [("descent", hold, t_down, "130"), ("slide", t_down + 4.0 * s, t_end, "0.4")]
        return [path_set(path), schedule_set(ramp)], t_end, phases
    if name == "half_speed":
        t_down = hold + 16.0 * s
        path = [(0, 0, 0), (hold, 0, 0), (t_down, 0, -0.8)]
        return [path_set(path), schedule_set(ramp)], t_down, [("descent", hold, t_down, "130")]
    if name == "stepped":  # (a) at rest: 0.1 mm steps at 0.1 m/s, each held 0.5 ms
        t = hold
        path = [(0, 0, 0), (hold, 0, 0)]
        phases = []
        for k in range(1, 9):
            t += 1.0 * s
            path.append((t, 0, -0.1 * k))
            t += 0.5 * s
            path.append((t, 0, -0.1 * k))
            phases.append(("step", t - 0.25 * s, t, "%.1f" % (PLATE_START_MM - 0.1 * k)))
        return [path_set(path), schedule_set(ramp)], t, phases
    if name == "field_sweep":
        t_down = hold + 6.0 * s
        t = t_down + 0.5 * s
        sched = list(ramp) + [(t, 130.0)]
        phases = [("descent", hold, t_down, "130"), ("field", t - 0.25 * s, t, "130")]
        for b in FIELD_LEVELS_MT[1:]:
            sched.append((t + 0.05 * s, b))
            t += 0.5 * s
            sched.append((t, b))
            phases.append(("field", t - 0.25 * s, t, str(b)))
        sched.append((t + 0.1 * s, 130.0))
        t_slide = t + 0.5 * s
        t_end = t_slide + 6.0 * s
        path = [(0, 0, 0), (hold, 0, 0), (t_down, 0, -0.6), (t_slide, 0, -0.6), (t_end, 1.5, -0.6)]
        phases.append(("slide", t_slide + 4.0 * s, t_end, "0.6"))
        return [path_set(path), schedule_set(sched)], t_end, phases
    raise ValueError("unknown protocol '%s' (compression, field_sweep, half_speed, stepped)" % name)


def parse_length_mm(text):
    t = text.strip().replace(" ", "")
    for unit, f in (("mm", 1.0), ("um", 1e-3), ("m", 1e3)):
        if t.endswith(unit):
            return float(t[: -len(unit)]) * f
    if float(t) == 0.0:
        return 0.0
    raise ValueError("--box %s: a length needs a unit: %s mm?" % (text, text))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("case", nargs="?", default=os.path.join(ROOT, "cases", "kawamoto_brush_compression.yaml"))
    p.add_argument("--diameters", type=int, nargs="+", default=[42, 50, 60], choices=sorted(COUNTS))
    p.add_argument("--protocols", nargs="+", default=["compression", "field_sweep", "half_speed"],
                   choices=["compression", "field_sweep", "half_speed", "stepped"])
    p.add_argument("--box", default="2mm", help="periodic square side (counts scale with its area)")
    p.add_argument("--time-scale", type=float, default=1.0, help="multiplies every protocol time")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="passed to every run")
    p.add_argument("--output", help="study folder (default <output.directory>/compression_study)")
    p.add_argument("--build", default=os.environ.get("BUILD_DIR", os.path.join(ROOT, "build")))
    p.add_argument("--dry-run", action="store_true", help="print the commands only")
    p.add_argument("--plot-only", action="store_true", help="only run the analysis on existing runs")
    a = p.parse_args()

    out = a.output or os.path.join("results", "compression_study")
    try:
        box = parse_length_mm(a.box)
    except ValueError as e:
        p.error(str(e))
    scale = (box / PAPER_AREA_MM) ** 2
    exe = os.path.join(a.build, "bin", "magbrush-dem")
    runs, rows = [], []
    for proto in a.protocols:
        diameters = [max(a.diameters)] if proto == "half_speed" else a.diameters
        for d in diameters:
            overrides, duration, phases = protocol(proto, a.time_scale)
            count = max(1, round(COUNTS[d] * scale))
            name = "%s_%dum" % (proto, d)
            sets = [
                "populations.carrier.diameter=%dum" % d,
                "populations.carrier.diameter_std=%gum" % (d / 10.0),
                "populations.carrier.count=%d" % count,
                "dem.periodic_length_x=%gmm" % box,
                "dem.periodic_length_y=%gmm" % box,
                "populations.carrier.insert_box=[[0mm, 0mm, 0.03mm], [%gmm, %gmm, %gmm]]" % (box, box, INSERT_TOP_MM),
                "dem.duration=%gms" % duration,
            ] + overrides + a.set
            cmd = [exe, a.case, "--output", os.path.join(out, "runs", name)]
            if a.threads:
                cmd += ["--threads", str(a.threads)]
            for s in sets:
                cmd += ["--set", s]
            runs.append((name, cmd))
            for ph in phases:
                rows.append([name, proto, d, count, "%g" % (box * box)] + list(ph))
    os.makedirs(out, exist_ok=True)
    # Keep the phases of earlier runs in this folder (studies can be run piecewise).
    proto_csv = os.path.join(out, "protocol.csv")
    ours = set(name for name, _ in runs)
    if os.path.exists(proto_csv):
        with open(proto_csv, newline="") as f:
            old = [r for r in csv.reader(f)][1:]
        rows = [r for r in old if r and r[0] not in ours] + rows
    with open(proto_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["run", "protocol", "diameter_um", "beads", "area_mm2", "phase", "t_start_ms", "t_end_ms", "label"])
        w.writerows(rows)
    timing = []
    if not a.plot_only:
        for name, cmd in runs:
            print("== %s\n%s" % (name, " ".join(shlex.quote(c) for c in cmd)), flush=True)
            if a.dry_run:
                continue
            os.makedirs(os.path.join(out, "runs", name), exist_ok=True)
            t0 = time.time()
            with open(os.path.join(out, "runs", name + ".log"), "w") as log:
                r = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT)
            timing.append((name, time.time() - t0, r.returncode))
            print("   %s: %.0f s wall, exit %d (log: %s.log)" % (name, timing[-1][1], r.returncode,
                                                               os.path.join(out, "runs", name)), flush=True)
            if r.returncode != 0:
                print("compression_study: %s failed; see its log" % name, file=sys.stderr)
                return r.returncode
        if timing:
            with open(os.path.join(out, "timing.csv"), "a", newline="") as f:
                csv.writer(f).writerows([[n, "%.1f" % t, rc] for n, t, rc in timing])
    if a.dry_run:
        return 0
    python = os.environ.get("MAGBRUSH_PYTHON", "/usr/bin/python3")
    return subprocess.run([python, os.path.join(HERE, "plot_compression.py"), out]).returncode


if __name__ == "__main__":
    sys.exit(main())
