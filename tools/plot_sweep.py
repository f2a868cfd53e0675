#!/usr/bin/env python3
"""Comparison plots of a `magbrush sweep`: each key number against the varied value, and the nip profiles of every point side by side.

    plot_sweep.py --dir RESULTS/sweep_NAME [--key KEY ...]

Reads sweep_summary.csv there (or, where the sweep ran --repeats, sweep_mean.csv: the mean of
each point's repeats with the standard error of their spread) and writes (atomically)
sweep_<key>.png for every key that has a
standard error, a physical bound (<key>_bound) or a measured comparison (or the keys named with
--key): the mean with its standard-error bars against the first varied value (in SI), the bound
as a dashed line, the measured points with their relative error and the within-tolerance flag,
the steady-state verdict of the key itself (where the runs tested it: its drift between the
halves of the window), of the whole run, and the run time of each point. A TMA study against
the bias also gets its straight line down to the development threshold, drawn in and kept in
sweep_tma_threshold.csv (tools/development_threshold.py). For nip scenes it also reads
sweep_profiles.csv and writes sweep_slip.png, sweep_pressure.png, sweep_density.png (Kawamoto
Fig. 17-19 and 22-27: one curve per point).
Exit status 3 when matplotlib is missing, 2 for unreadable inputs.
"""
import argparse
import csv
import os
import sys

import development_threshold
from magbrush_plots import pyplot


def read(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    return rows[0], rows[1:]


def save(fig, path):
    tmp = path + ".tmp"
    fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    os.replace(tmp, path)


number = development_threshold.number  # a table cell as a float, NaN when it is none


def verdicts(col, r, key):
    """The point's steady-state verdicts: this key's own (where the run tested it: its drift
    between the halves of the window, under 2 % = steady, beyond two of its standard errors =
    drifting, else undecided), the whole run's (every tested key), and the run time."""
    steady = r[col["steady_state"]] if "steady_state" in col else "nan"
    trend = r[col["significant_drift"]] if "significant_drift" in col else "nan"
    run = r[col["run_time_s"]] if "run_time_s" in col else "?"
    verdict = ("steady" if steady == "1" else "steady ?" if steady != "0" else
               "undecided (noise)" if trend == "0" else "NOT steady")
    if key + "_drift" not in col:
        return f"{verdict}, {run} s"
    drift = number(r[col[key + "_drift"]])
    error = number(r[col[key + "_drift_stderr"]]) if key + "_drift_stderr" in col else float("nan")
    if drift != drift:
        return f"{key} not tested; run {verdict}, {run} s"
    own = ("steady" if abs(drift) < 0.02 else "drifting" if error == error and abs(drift) > 2 * error
           else "undecided (noise)")
    spread = f" ± {100 * error:.1f}" if error == error else ""
    return f"{key} {own} (drift {100 * drift:+.1f}{spread} %); run {verdict}, {run} s"


def draw_threshold(ax, directory, header, rows, xs):
    """A TMA study against the bias: the straight line through its points down to its
    development threshold (tools/development_threshold.py), kept in sweep_tma_threshold.csv."""
    result = development_threshold.study_threshold(header, rows)
    if result is None:
        return
    path = os.path.join(directory, "sweep_tma_threshold.csv")
    development_threshold.write_csv(path, result)
    print(f"  threshold   {path}: {development_threshold.describe(result)}")
    x0 = result["threshold"]
    if x0 != x0:
        return
    # Down to the threshold when it lies within one span of the points; a threshold farther
    # off (two points with a large intercept) would squeeze the points' ticks together, so the
    # line then stops a fifth of the span past them and the legend gives the threshold.
    finite = [x for x in xs if x == x]
    lo, hi = min(finite), max(finite)
    span = hi - lo
    near = lo - span <= x0 <= hi + span
    ends = [min(lo, x0), max(hi, x0)] if near else [lo - 0.2 * span, hi + 0.2 * span]
    ax.plot(ends, [result["intercept"] + result["slope"] * x for x in ends], ":", color="C1",
            label=development_threshold.describe(result) + ("" if near else " (off the axis)"))
    cz = result["contrast_zero"]
    if cz == cz and ends[0] - 0.05 * span <= cz <= ends[1] + 0.05 * span:
        ax.axvline(result["contrast_zero"], color="0.6", lw=0.8, ls="-.",
                   label=f"zero contrast (the bound vanishes): {result['contrast_zero']:.0f} V")


def plot_keys(plt, directory, header, rows, requested):
    """One plot per key: mean ± standard error against the first varied value (SI)."""
    col = {name: i for i, name in enumerate(header)}
    x_columns = [h for h in header if " [" in h and h.endswith("]")]
    if not x_columns or not rows:
        return
    x_name = x_columns[0]
    xs = [number(r[col[x_name]]) for r in rows]
    if any(x != x for x in xs):
        return  # the varied value is not a number: no axis to plot against
    keys = list(requested)
    for h in header:
        base = None
        if h.endswith("_stderr"):
            base = h[: -len("_stderr")]
        elif h.endswith("_bound"):
            base = h[: -len("_bound")]
        elif h.startswith("measured_"):
            base = h[len("measured_"):]
        if base and base.endswith("_drift") and base[: -len("_drift")] in col:
            continue  # a key's steady-state drift: shown in that key's own plot
        if base and base in col and base not in keys:
            keys.append(base)
    for key in keys:
        if key not in col:
            print(f"plot_sweep.py: no column '{key}' in the sweep summary", file=sys.stderr)
            continue
        ys = [number(r[col[key]]) for r in rows]
        errors = [number(r[col[key + "_stderr"]]) if key + "_stderr" in col else 0.0 for r in rows]
        errors = [0.0 if e != e else e for e in errors]
        fig, ax = plt.subplots(figsize=(7, 4.2))
        if "repeats" in col:
            counts = sorted({r[col["repeats"]] for r in rows})
            label = f"magbrush, mean of {'/'.join(counts)} repeats (± standard error of their spread)"
        else:
            label = "magbrush (± standard error)"
        ax.errorbar(xs, ys, yerr=errors, fmt="o-", capsize=4, label=label)
        if key + "_bound" in col:
            bound = [number(r[col[key + "_bound"]]) for r in rows]
            # Values far below their bound (a transient's TMA at 1 % of the neutralisation
            # bound) would lie flat on the axis: a log scale shows both (a zero bound, at zero
            # contrast, is then left out of the line).
            finite = [b for b in bound if b == b and b > 0]
            log = bool(finite) and all(y == y and y > 0 for y in ys) and max(ys) < 0.05 * max(finite)
            if log:
                ax.set_yscale("log")
                bound = [b if b > 0 else float("nan") for b in bound]
            # Through the points that have one: a point not run (NaN) would break the line
            # into single points, which a dashed line does not draw.
            drawn = [(x, b) for x, b in zip(xs, bound) if b == b]
            ax.plot([x for x, _ in drawn], [b for _, b in drawn], "k--", lw=1.2, label="physical bound")
            if log:
                ax.plot([], [], " ", label="log scale: the values lie below 5 % of the bound")
        if key == "tma_kg_per_m2":
            draw_threshold(ax, directory, header, rows, xs)
        measured = "measured_" + key
        if measured in col:
            mys = [number(r[col[measured]]) for r in rows]
            ax.plot(xs, mys, "s", mfc="none", mec="C3", ms=8, label="measured")
            flag = [h for h in header if h.startswith("within_") and h.endswith("_" + key)]
            errs = [number(r[col["relative_error_" + key]]) for r in rows]
            for x, y, e, r in zip(xs, mys, errs, rows):
                if e == e:
                    ok = flag and r[col[flag[0]]] == "1"
                    ax.annotate(f"{100 * e:+.1f} %" + (" ✓" if ok else " ✗"), (x, y), textcoords="offset points",
                                xytext=(6, -12), fontsize=8, color="C2" if ok else "C3")
        # Each point as the user gave it ("144deg", "0.4mm"), on the axis and in the verdicts;
        # the axis itself is in SI so that the points are spaced by their values.
        given = x_name.rsplit(" [", 1)[0]
        labels = [r[col[given]] for r in rows] if given in col else [f"{x:g}" for x in xs]
        notes = [f"{label}: {verdicts(col, r, key)}" for label, r in zip(labels, rows)]
        ax.set_title("\n".join(notes) if key + "_drift" in col else "; ".join(notes), fontsize=7)
        if len(set(xs)) == len(xs) and len(xs) <= 12:
            ax.set_xticks(xs)
            ax.set_xticklabels(labels)
            ax.set_xlabel(given)
        else:
            ax.set_xlabel(x_name)
        ax.set_ylabel(key)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        path = os.path.join(directory, f"sweep_{key}.png")
        save(fig, path)
        plt.close(fig)
        print(f"  plot        {path}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", required=True)
    p.add_argument("--key", action="append", default=[], help="a summary key to plot (repeatable)")
    args = p.parse_args()
    plt = pyplot("plot_sweep.py")
    if plt is None:
        return 3
    table = "sweep_mean.csv" if os.path.exists(os.path.join(args.dir, "sweep_mean.csv")) else "sweep_summary.csv"
    try:
        summary_header, summary_rows = read(os.path.join(args.dir, table))
    except (OSError, IndexError) as e:
        print(f"plot_sweep.py: cannot read the sweep summary: {e}", file=sys.stderr)
        return 2
    plot_keys(plt, args.dir, summary_header, summary_rows, args.key)
    try:
        header, rows = read(os.path.join(args.dir, "sweep_profiles.csv"))
    except (OSError, IndexError):
        return 0  # not a nip scene: no profiles to compare
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
