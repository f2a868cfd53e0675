#!/usr/bin/env python3
"""Two cases' sleeve-flux profiles overlaid, with each pole's peak shift, written as a PNG.

Called by `magbrush flux CASE --compare OTHER` with the files it writes:

    plot_flux_compare.py --profiles flux_compare.csv --peaks flux_compare_peaks.csv
                         [--label-a TEXT] [--label-b TEXT] -o flux_compare.png

Top: Bn and Bt of A (solid) and B (dashed) against the angle, each pole's peak marked in both
and labelled with its shift (angle, change of |Bn|); bottom: B − A. Exit status 3 when matplotlib is
missing (the caller then warns and carries on), 2 for unreadable files.
"""
import argparse
import math
import os
import sys

from magbrush_plots import pyplot, read_columns


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profiles", required=True, help="flux_compare.csv")
    parser.add_argument("--peaks", required=True, help="flux_compare_peaks.csv")
    parser.add_argument("--label-a", default="A")
    parser.add_argument("--label-b", default="B")
    parser.add_argument("-o", "--output", required=True, help="PNG file to write")
    args = parser.parse_args()

    plt = pyplot("plot_flux_compare.py")
    if plt is None:
        return 3
    try:
        p = read_columns(args.profiles)
        peaks = read_columns(args.peaks)
    except (OSError, ValueError, IndexError) as e:
        print(f"plot_flux_compare.py: cannot read {e}", file=sys.stderr)
        return 2

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.4]})
    a = p["angle_deg"]
    top.plot(a, p["Bn_A_mT"], "-", lw=1.2, color="tab:blue", label=f"Bn {args.label_a}")
    top.plot(a, p["Bn_B_mT"], "--", lw=1.2, color="navy", label=f"Bn {args.label_b}")
    top.plot(a, p["Bt_A_mT"], "-", lw=1.0, color="tab:orange", label=f"Bt {args.label_a}")
    top.plot(a, p["Bt_B_mT"], "--", lw=1.0, color="saddlebrown", label=f"Bt {args.label_b}")
    bottom.plot(a, p["dBn_mT"], "-", lw=1.0, color="tab:blue", label="Bn: B − A")
    bottom.plot(a, p["dBt_mT"], "-", lw=0.9, color="tab:orange", label="Bt: B − A")
    # Each pole's peak in both, and what moved.
    for k, pole in enumerate(peaks["pole"]):
        xa, ya, xb, yb = (peaks[c][k] for c in ("angle_A_deg", "Bn_A_mT", "angle_B_deg", "Bn_B_mT"))
        if not all(math.isfinite(v) for v in (xa, ya, xb, yb)):
            continue
        top.plot([xa], [ya], "o", ms=4, color="tab:blue")
        top.plot([xb], [yb], "s", ms=4, mfc="none", color="navy")
        shift, change = peaks["shift_deg"][k], peaks["peak_change_percent"][k]
        top.annotate(f"{pole}\n{shift:+.2f}°, {change:+.1f} %", (xb, yb),
                     textcoords="offset points", xytext=(0, 8 if yb > 0 else -22),
                     ha="center", fontsize=7)
    for ax in (top, bottom):
        ax.axhline(0, color="0.6", lw=0.6)
        ax.grid(alpha=0.3)
    top.set_ylabel("flux density [mT]")
    bottom.set_ylabel("B − A [mT]")
    bottom.set_xlabel("angle [deg] (counter-clockwise from +x)")
    top.set_title("Sleeve flux: A and B, each pole's peak shift (B − A: angle, |Bn| in %)")
    top.set_xlim(0, 360)
    top.margins(y=0.18)  # room for the labels of the peaks at the top and the bottom
    top.legend(fontsize=7, ncol=2)
    bottom.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    # Atomic: a half-written PNG never replaces a good one.
    tmp = f"{args.output}.tmp{os.getpid()}.png"
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
