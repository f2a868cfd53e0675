#!/usr/bin/env python3
"""The designed sleeve profile against its target band, written as a PNG.

Called by `magbrush design poles` with the files it writes:

    plot_design.py --profile design_profile.csv --bands design_bands.csv
                   [--target design_target_profile.csv] [--title TEXT] -o design_profile.png

Top: Bn and Bt of the designed layout (exact ring, lines; the FEM check dashed when present;
the case's layout thin grey), a profile target as its band (target ± tolerance), a
specification's pole boxes (peak angle ± tolerance by peak ± tolerance) on Bn. Bottom: |B|
with the arcs where it must stay below a level and the arc where the layer must be released. Exit status 3 when matplotlib is missing
(the caller then warns and carries on), 2 for bad arguments or unreadable files.
"""
import argparse
import math
import sys

from magbrush_plots import pyplot, read_columns


def finite(values):
    return any(isinstance(v, float) and math.isfinite(v) for v in values)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profile", required=True)
    parser.add_argument("--bands", required=True)
    parser.add_argument("--target")
    parser.add_argument("--title", default="Designed sleeve flux")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()
    plt = pyplot("plot_design.py")
    if plt is None:
        return 3
    from matplotlib.patches import Rectangle
    try:
        p = read_columns(args.profile)
        bands = read_columns(args.bands)
        target = read_columns(args.target) if args.target else None
    except (OSError, ValueError, IndexError) as e:
        print(f"plot_design.py: cannot read the input: {e}", file=sys.stderr)
        return 2

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(11, 7.5), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.6]})
    a = p["angle_deg"]
    top.plot(a, p["Bn_case_mT"], "-", lw=0.8, color="0.7", label="Bn, the case's layout")
    if target:
        t = target["angle_deg"]
        lo = [b - w for b, w in zip(target["Bn_target_mT"], target["tolerance_mT"])]
        hi = [b + w for b, w in zip(target["Bn_target_mT"], target["tolerance_mT"])]
        top.fill_between(t, lo, hi, color="tab:blue", alpha=0.25, lw=0, label="Bn target ± tolerance")
        if finite(target["Bt_target_mT"]):
            lo = [b - w for b, w in zip(target["Bt_target_mT"], target["tolerance_mT"])]
            hi = [b + w for b, w in zip(target["Bt_target_mT"], target["tolerance_mT"])]
            top.fill_between(t, lo, hi, color="tab:orange", alpha=0.25, lw=0, label="Bt target ± tolerance")
    top.plot(a, p["Bn_mT"], "-", lw=1.3, color="tab:blue", label="Bn designed (exact ring)")
    top.plot(a, p["Bt_mT"], "-", lw=1.0, color="tab:orange", label="Bt designed (exact ring)")
    if finite(p["Bn_fem_mT"]):
        top.plot(a, p["Bn_fem_mT"], "--", lw=1.0, color="k", label="Bn designed (FEM check)")
    bottom.plot(a, p["B_mT"], "-", lw=1.2, color="tab:green", label="|B| designed")
    for kind, f, t, lo, hi, label in zip(bands["kind"], bands["from_deg"], bands["to_deg"],
                                         bands["low_mT"], bands["high_mT"], bands["label"]):
        for shift in (-360.0, 0.0, 360.0):  # an arc may cross 0°
            x0, x1 = f + shift, t + shift
            if x1 < 0 or x0 > 360:
                continue
            if kind == "Bn_peak":
                if lo == hi:  # an angle requirement only: a vertical band
                    top.axvspan(x0, x1, color="tab:red", alpha=0.15)
                else:
                    top.add_patch(Rectangle((x0, lo), x1 - x0, hi - lo, fill=False, ec="tab:red", lw=1.5))
                top.annotate(str(label), ((x0 + x1) / 2, hi if hi > 0 else lo), color="tab:red",
                             ha="center", va="bottom" if hi > 0 else "top", fontsize=8)
            elif kind == "release":  # somewhere on the arc the layer must be let go
                bottom.axvspan(x0, x1, color="tab:purple", alpha=0.15, label=str(label) if shift == 0.0 else None)
            else:
                bottom.hlines(hi, x0, x1, color="tab:red", lw=2)
                bottom.axvspan(x0, x1, color="tab:red", alpha=0.1)
    top.set_ylabel("B [mT]")
    top.axhline(0, color="0.5", lw=0.5)
    top.legend(fontsize=8, loc="upper right", ncol=2)
    top.set_title(args.title, fontsize=10)
    bottom.set_ylabel("|B| [mT]")
    bottom.set_xlabel("angle [deg] (counter-clockwise from +x)")
    bottom.set_xlim(0, 360)
    bottom.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
