#!/usr/bin/env python3
"""Analysis and plots of Kawamoto's compression study (tools/compression_study).

    plot_compression.py STUDY_DIR

reads STUDY_DIR/protocol.csv (the phase windows of every run) and each run's
runs/<run>/plate_compression.csv and contact maps, and writes into STUDY_DIR:

  force_vs_length.csv / .png   normal force [mN] against brush length at 130 mT (descent,
                               binned by 0.05 mm), tangential force at the slide's length
                               (Kawamoto Fig. 5); force_at_rest.csv: the held steps of `stepped`
  force_vs_field.csv / .png    normal force against B at 0.6 mm, with the low-field exponent
                               of F ~ B^k (Fig. 6)
  tangential.csv               sliding: normal, tangential force and their ratio
  chains.csv, chain_spacing.png    touching density [1/mm^2], mean force per touching bead [uN],
                               chain spacing l/sqrt(n) [um] against diameter at 0.4 and 0.6 mm,
                               with the fitted power laws (Fig. 10, 12)
  fig12_density_force.png      density and force per bead against d (Fig. 12)
  contact_map_<run>.png        beads touching the plate at the end of the descent (Fig. 9)
  quasi_static.csv             force at equal lengths at full and half plate speed
  summary.txt                  the figures quoted in docs/compression_study.md

Uses numpy and matplotlib (Agg). Exit 2 for missing inputs, 3 when numpy/matplotlib are missing.
"""
import csv
import glob
import math
import os
import sys

try:
    import numpy as np
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:  # pragma: no cover
    print("plot_compression.py: needs numpy and matplotlib (%s); run it with /usr/bin/python3" % e, file=sys.stderr)
    sys.exit(3)

BIN_MM = 0.05


def read_table(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    header, data = rows[0], rows[1:]
    cols = {}
    for i, name in enumerate(header):
        try:
            cols[name] = np.array([float(r[i]) for r in data])
        except ValueError:
            cols[name] = [r[i] for r in data]
    return cols


def window(d, t0_ms, t1_ms):
    t = d["time_s"] * 1e3
    return (t >= t0_ms) & (t <= t1_ms)


def power_fit(x, y):
    """Exponent and prefactor of y = c x^k (least squares in logs)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = (x > 0) & (y > 0)
    if ok.sum() < 2:
        return float("nan"), float("nan")
    k, lnc = np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)
    return k, math.exp(lnc)


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for r in rows:
            w.writerow([("%.6g" % v) if isinstance(v, float) else v for v in r])


def main():
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    study = sys.argv[1]
    proto_path = os.path.join(study, "protocol.csv")
    if not os.path.exists(proto_path):
        print("plot_compression.py: no %s (run tools/compression_study first)" % proto_path, file=sys.stderr)
        return 2
    phases = read_table(proto_path)
    runs = {}
    for i, run in enumerate(phases["run"]):
        path = os.path.join(study, "runs", run, "plate_compression.csv")
        if not os.path.exists(path):
            continue
        r = runs.setdefault(run, {"data": read_table(path), "protocol": phases["protocol"][i],
                                  "d": int(phases["diameter_um"][i]), "area": float(phases["area_mm2"][i]),
                                  "dir": os.path.join(study, "runs", run), "phases": []})
        r["phases"].append((phases["phase"][i], float(phases["t_start_ms"][i]), float(phases["t_end_ms"][i]),
                            phases["label"][i]))
    if not runs:
        print("plot_compression.py: no finished runs under %s/runs" % study, file=sys.stderr)
        return 2
    summary = []

    # ---- (a) normal force against brush length (descent, binned), (c) tangential at the slide
    length_rows, tangential_rows, chain_rows, step_rows = [], [], [], []
    curves, steps = {}, {}
    for name, r in sorted(runs.items()):
        d = r["data"]
        for ph, t0, t1, label in r["phases"]:
            m = window(d, t0, t1)
            if not m.any():
                continue
            if ph == "descent":
                L = d["brush_length_m"][m] * 1e3
                edges = np.arange(math.floor(L.min() / BIN_MM) * BIN_MM, L.max() + BIN_MM, BIN_MM)
                pts = []
                for lo in edges:
                    b = (L >= lo) & (L < lo + BIN_MM)
                    if b.sum() == 0:
                        continue
                    fn = d["Fn_N"][m][b].mean() * 1e3
                    n = d["touching"][m][b].mean()
                    pts.append((lo + BIN_MM / 2, fn))
                    length_rows.append([name, r["protocol"], r["d"], lo + BIN_MM / 2, fn, fn / r["area"], n,
                                        n / r["area"], (fn * 1e3 / n) if n > 0 else 0.0,
                                        math.sqrt(r["area"] / n) * 1e3 if n > 0 else 0.0])
                curves[name] = (r, pts)
            elif ph == "step":
                L = d["brush_length_m"][m].mean() * 1e3
                fn = d["Fn_N"][m].mean() * 1e3
                n = d["touching"][m].mean()
                steps.setdefault(name, (r, []))[1].append((L, fn))
                step_rows.append([name, r["d"], L, fn, fn / r["area"], n, n / r["area"],
                                  (fn * 1e3 / n) if n > 0 else 0.0])
            elif ph == "slide":
                fn, ft = d["Fn_N"][m].mean() * 1e3, d["Ft_N"][m].mean() * 1e3
                tangential_rows.append([name, r["d"], float(label), fn, ft, ft / fn if fn > 0 else float("nan")])
    write_csv(os.path.join(study, "force_vs_length.csv"),
              ["run", "protocol", "diameter_um", "brush_length_mm", "Fn_mN", "pn_kPa", "touching", "density_per_mm2",
               "force_per_bead_uN", "chain_spacing_um"], length_rows)
    write_csv(os.path.join(study, "force_at_rest.csv"),
              ["run", "diameter_um", "brush_length_mm", "Fn_mN", "pn_kPa", "touching", "density_per_mm2",
               "force_per_bead_uN"], step_rows)
    write_csv(os.path.join(study, "tangential.csv"),
              ["run", "diameter_um", "brush_length_mm", "Fn_mN", "Ft_mN", "Ft_over_Fn"], tangential_rows)
    for row in tangential_rows:
        summary.append("sliding %s at %.2f mm: Fn %.3g mN, Ft %.3g mN, Ft/Fn %.3f" % (row[0], row[2], row[3], row[4],
                                                                                      row[5]))

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for name, (r, pts) in sorted(curves.items()):
        if not pts:
            continue
        x, y = zip(*pts)
        style = "--" if r["protocol"] == "half_speed" else "-"
        ax.plot(x, y, style, marker="o", ms=3, label="normal, %d um (%s)" % (r["d"], r["protocol"]))
    for name, (r, pts) in sorted(steps.items()):
        x, y = zip(*pts)
        ax.plot(x, y, "D-", ms=5, lw=2, label="normal at rest (held steps), %d um" % r["d"])
    for row in tangential_rows:
        ax.plot([row[2]], [row[4]], "s", ms=7, label="tangential, %d um, %.1f mm" % (row[1], row[2]))
    ax.set_xlabel("brush length [mm]")
    ax.set_ylabel("force on the plate [mN]")
    ax.set_title("Normal and tangential force vs brush length, 130 mT (Kawamoto Fig. 5)", fontsize=10)
    ax.invert_xaxis()
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(study, "force_vs_length.png"), dpi=130)
    plt.close(fig)

    # ---- quasi-static check: the same diameter at full and half speed, at equal lengths
    qs = []
    byd = {}
    for name, (r, pts) in curves.items():
        byd.setdefault(r["d"], {})[r["protocol"]] = dict((round(x, 3), y) for x, y in pts)
    for dia, p in sorted(byd.items()):
        if "half_speed" in p and "compression" in p:
            for L in sorted(set(p["half_speed"]) & set(p["compression"])):
                qs.append([dia, L, p["compression"][L], p["half_speed"][L],
                           p["compression"][L] / p["half_speed"][L] if p["half_speed"][L] > 0 else float("nan")])
    write_csv(os.path.join(study, "quasi_static.csv"),
              ["diameter_um", "brush_length_mm", "Fn_full_speed_mN", "Fn_half_speed_mN", "ratio"], qs)
    if qs:
        ratios = [q[4] for q in qs if q[1] <= 0.9 and not math.isnan(q[4])]
        if ratios:
            summary.append("quasi-static check (full/half speed, lengths <= 0.9 mm): mean %.3f, min %.3f, max %.3f"
                           % (np.mean(ratios), min(ratios), max(ratios)))

    # ---- equal brush length across diameters
    for L in (0.4, 0.5, 0.6, 0.7, 0.8):
        vals = {}
        for name, (r, pts) in curves.items():
            if r["protocol"] != "compression":
                continue
            for x, y in pts:
                if abs(x - L - BIN_MM / 2) < 1e-6 or abs(x - L) < BIN_MM / 2 - 1e-9:
                    vals[r["d"]] = y
        if len(vals) >= 2:
            mean = np.mean(list(vals.values()))
            spread = max(abs(v / mean - 1) for v in vals.values())
            summary.append("brush length %.2f mm: Fn %s mN, max deviation from the mean %.1f %%" % (
                L, ", ".join("%d um %.3g" % (k, v) for k, v in sorted(vals.items())), 100 * spread))

    # ---- (b) normal force against B at 0.6 mm
    field_rows = []
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for name, r in sorted(runs.items()):
        pts = []
        for ph, t0, t1, label in r["phases"]:
            if ph != "field":
                continue
            m = window(r["data"], t0, t1)
            if not m.any():
                continue
            B = r["data"]["B_T"][m].mean() * 1e3
            fn = r["data"]["Fn_N"][m].mean() * 1e3
            n = r["data"]["touching"][m].mean()
            pts.append((B, fn))
            field_rows.append([name, r["d"], B, fn, n, (fn * 1e3 / n) if n > 0 else 0.0])
        if pts:
            pts.sort()
            B, F = zip(*pts)
            low = [(b, f) for b, f in pts if b <= 50.5]
            k_low, _ = power_fit(*zip(*low)) if len(low) >= 2 else (float("nan"), 0)
            k_all, _ = power_fit(B, F)
            summary.append("field sweep %s: F ~ B^%.2f (B <= 50 mT), B^%.2f (all levels); F(130 mT) = %.3g mN"
                           % (name, k_low, k_all, F[-1]))
            ax.loglog(B, F, "o-", label="%d um (low-field exponent %.2f)" % (r["d"], k_low))
    if field_rows:
        bb = np.array([15, 130.0])
        ref = max(r[3] for r in field_rows if abs(r[2] - 130) < 1)
        ax.loglog(bb, ref * (bb / 130) ** 2, "k:", label="B^2")
        ax.set_xlabel("applied flux density B [mT]")
        ax.set_ylabel("normal force [mN]")
        ax.set_title("Normal force vs B at a brush length of 0.6 mm (Kawamoto Fig. 6)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(study, "force_vs_field.png"), dpi=130)
    plt.close(fig)
    write_csv(os.path.join(study, "force_vs_field.csv"),
              ["run", "diameter_um", "B_mT", "Fn_mN", "touching", "force_per_bead_uN"], field_rows)

    # ---- chains on the plate against diameter (Fig. 10, 12): at 0.4 mm (end of the descent of
    # `compression`) and at 0.6 mm, 130 mT (`field_sweep`)
    for target, proto in ((0.4, "compression"), (0.6, "field_sweep")):
        for row in length_rows:
            if row[1] == proto and abs(row[3] - target) < BIN_MM / 2 + 1e-9:
                chain_rows.append([row[2], target, row[7], row[8], row[9], row[4]])
    chain_rows.sort()
    write_csv(os.path.join(study, "chains.csv"),
              ["diameter_um", "brush_length_mm", "density_per_mm2", "force_per_bead_uN", "chain_spacing_um", "Fn_mN"],
              chain_rows)
    if chain_rows:
        fig, ax = plt.subplots(1, 2, figsize=(10, 4))
        fig2, ax2 = plt.subplots(figsize=(5.5, 4))
        for target in sorted(set(r[1] for r in chain_rows)):
            rows = [r for r in chain_rows if r[1] == target]
            d = [r[0] for r in rows]
            if len(d) >= 2:
                kd, _ = power_fit(d, [r[2] for r in rows])
                kf, _ = power_fit(d, [r[3] for r in rows])
                ks, _ = power_fit(d, [r[4] for r in rows])
                summary.append("at %.1f mm: touching density ~ d^%.2f, force per bead ~ d^%.2f, spacing ~ d^%.2f "
                               "(ideal -2, 2, 1); density x d^2 spread %s" % (
                                   target, kd, kf, ks,
                                   ", ".join("%.3g" % (r[2] * r[0] ** 2 / (rows[-1][2] * rows[-1][0] ** 2)) for r in rows)))
            ax[0].plot(d, [r[2] for r in rows], "o-", label="%.1f mm" % target)
            ax[1].plot(d, [r[3] for r in rows], "o-", label="%.1f mm" % target)
            ax2.plot(d, [r[4] for r in rows], "o-", label="%.1f mm" % target)
        ax[0].set_ylabel("beads touching the plate [1/mm^2]")
        ax[1].set_ylabel("mean normal force per touching bead [uN]")
        for a_ in ax:
            a_.set_xlabel("carrier diameter [um]")
            a_.grid(alpha=0.3)
            a_.legend(fontsize=8)
        fig.suptitle("Touching density and force per bead, 130 mT (Kawamoto Fig. 12)")
        fig.tight_layout()
        fig.savefig(os.path.join(study, "fig12_density_force.png"), dpi=130)
        ax2.set_xlabel("carrier diameter [um]")
        ax2.set_ylabel("chain spacing l/sqrt(n) [um]")
        ax2.set_title("Chain spacing on the plate, 130 mT (Kawamoto Fig. 10)", fontsize=10)
        ax2.grid(alpha=0.3)
        ax2.legend(fontsize=8)
        fig2.tight_layout()
        fig2.savefig(os.path.join(study, "chain_spacing.png"), dpi=130)
        plt.close(fig)
        plt.close(fig2)

    # ---- contact maps (Fig. 9): the map closest to the end of each run's descent
    for name, r in sorted(runs.items()):
        index = os.path.join(r["dir"], "contact_maps.csv")
        if r["protocol"] != "compression" or not os.path.exists(index):
            continue
        maps = read_table(index)
        t_end = [t1 for ph, t0, t1, _ in r["phases"] if ph == "descent"][0]
        k = int(np.argmin(np.abs(maps["time_s"] * 1e3 - t_end)))
        m = read_table(os.path.join(r["dir"], maps["file"][k]))
        fig, ax = plt.subplots(figsize=(5.5, 5))
        if len(m.get("Fn_N", [])):
            sc = ax.scatter(m["x_m"] * 1e3, m["y_m"] * 1e3, s=8 + 200 * m["Fn_N"] / m["Fn_N"].max(),
                            c=m["Fn_N"] * 1e6, cmap="viridis")
            ax.quiver(m["x_m"] * 1e3, m["y_m"] * 1e3, m["Ft_x_N"], m["Ft_y_N"], color="r", width=0.003)
            fig.colorbar(sc, ax=ax, label="normal force per bead [uN]")
        side = math.sqrt(r["area"])
        ax.set_xlim(0, side)
        ax.set_ylim(0, side)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title("%d um beads on the plate, %.2f mm, %.0f mT (Fig. 9)" % (
            r["d"], maps["brush_length_m"][k] * 1e3, maps["B_T"][k] * 1e3), fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(study, "contact_map_%s.png" % name), dpi=130)
        plt.close(fig)

    with open(os.path.join(study, "summary.txt"), "w") as f:
        f.write("\n".join(summary) + "\n")
    print("\n".join(summary))
    print("plot_compression.py: wrote CSV and PNG files into %s" % study)
    return 0


if __name__ == "__main__":
    sys.exit(main())
