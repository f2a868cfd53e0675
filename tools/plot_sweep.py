#!/usr/bin/env python3
"""Comparison plots of a `magbrush sweep`: the nip profiles of every point side by side.

    plot_sweep.py --dir RESULTS/sweep_NAME

Reads sweep_profiles.csv and sweep_summary.csv there and writes (atomically) sweep_slip.png,
sweep_pressure.png, sweep_density.png (Kawamoto Fig. 17-19 and 22-27: one curve per point).
Exit status 3 when matplotlib is missing, 2 for unreadable inputs.
"""
import argparse
import csv
import os
import sys


def read(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    return rows[0], rows[1:]


def save(fig, path):
    tmp = path + ".tmp"
    fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    os.replace(tmp, path)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", required=True)
    args = p.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        print(f"plot_sweep.py: {e}", file=sys.stderr)
        return 3
    try:
        header, rows = read(os.path.join(args.dir, "sweep_profiles.csv"))
    except (OSError, IndexError) as e:
        print(f"plot_sweep.py: cannot read the sweep profiles: {e}", file=sys.stderr)
        return 2
    col = {name: i for i, name in enumerate(header)}
    points = []
    for r in rows:
        if r[0] not in points:
            points.append(r[0])

    def series(point, name, scale=1.0):
        xs, ys = [], []
        for r in rows:
            if r[0] == point:
                try:
                    xs.append(float(r[col["x_mm"]]))
                    ys.append(float(r[col[name]]) * scale)
                except ValueError:
                    pass
        return xs, ys

    plots = [("sweep_slip.png", "slip_speed_m_s", 1.0, "slip speed of the beads touching the drum [m/s]"),
             ("sweep_pressure.png", "normal_pressure_Pa", 1e-3, "normal pressure on the drum [kPa]"),
             ("sweep_density.png", "density_per_mm2", 1.0, "beads touching the drum [1/mm²]")]
    for name, column, scale, ylabel in plots:
        fig, ax = plt.subplots(figsize=(7, 4))
        for point in points:
            xs, ys = series(point, column, scale)
            ax.plot(xs, ys, "o-", ms=3, label=point)
        ax.axvline(0, color="0.7", lw=0.8)
        ax.set_xlabel("x along the nip from the gap centre [mm] (positive downstream)")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        save(fig, os.path.join(args.dir, name))
        plt.close(fig)
        print(f"  plot        {os.path.join(args.dir, name)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
