#!/usr/bin/env python3
"""Overlay of a measured sleeve flux profile and the computed one(s), written as a PNG.

Called by `magbrush flux` with the residual files it writes (angle_deg, Bn_measured_mT,
Bn_computed_mT, Bn_residual_mT[, Bt_measured_mT, Bt_computed_mT, Bt_residual_mT]):

    plot_flux.py --residuals flux_residuals.csv [--fitted flux_fit_residuals.csv]
                 [--title TEXT] [--label LABEL] -o flux_overlay.png

Top: Bn and Bt against the angle (measured as points, computed as lines, the fitted model
dashed, at the measured points even when the fit found an encoder offset); bottom: the
residuals. Exit status 3 when matplotlib is missing (the caller then
warns and carries on), 2 for bad arguments or unreadable files.
"""
import argparse
import os
import sys

from magbrush_plots import pyplot, read_columns


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--residuals", required=True, help="residual CSV of the compared model")
    parser.add_argument("--fitted", help="residual CSV of the fitted model (optional)")
    parser.add_argument("--title", default="Sleeve flux density")
    parser.add_argument("--label", default="computed", help="legend label of the compared model")
    parser.add_argument("-o", "--output", required=True, help="PNG file to write")
    args = parser.parse_args()

    plt = pyplot("plot_flux.py")
    if plt is None:
        return 3

    try:
        base = read_columns(args.residuals)
        fitted = read_columns(args.fitted) if args.fitted else None
    except (OSError, ValueError, IndexError) as e:
        print(f"plot_flux.py: cannot read the residual file: {e}", file=sys.stderr)
        return 2

    has_bt = "Bt_measured_mT" in base
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 7), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 1.4]})
    a = base["angle_deg"]
    top.plot(a, base["Bn_measured_mT"], ".", ms=3, color="tab:blue", label="Bn measured")
    top.plot(a, base["Bn_computed_mT"], "-", lw=1.2, color="tab:blue", label=f"Bn {args.label}")
    bottom.plot(a, base["Bn_residual_mT"], "-", lw=0.9, color="tab:blue",
                label=f"Bn measured − {args.label}")
    if has_bt:
        top.plot(a, base["Bt_measured_mT"], ".", ms=3, color="tab:orange", label="Bt measured")
        top.plot(a, base["Bt_computed_mT"], "-", lw=1.2, color="tab:orange",
                 label=f"Bt {args.label}")
        bottom.plot(a, base["Bt_residual_mT"], "-", lw=0.9, color="tab:orange",
                    label=f"Bt measured − {args.label}")
    if fitted:
        # The fitted residuals are at the scan's angles rotated by the fitted encoder offset;
        # drawn at the scan's own angles (same samples, same order) they sit on the measured
        # points above instead of beside them.
        fa = a if len(fitted["angle_deg"]) == len(a) else fitted["angle_deg"]
        top.plot(fa, fitted["Bn_computed_mT"], "--", lw=1.0, color="navy", label="Bn fitted")
        bottom.plot(fa, fitted["Bn_residual_mT"], "--", lw=0.9, color="navy",
                    label="Bn measured − fitted")
        if "Bt_computed_mT" in fitted:
            top.plot(fa, fitted["Bt_computed_mT"], "--", lw=1.0, color="saddlebrown",
                     label="Bt fitted")
            bottom.plot(fa, fitted["Bt_residual_mT"], "--", lw=0.9, color="saddlebrown",
                        label="Bt measured − fitted")
    top.axhline(0, color="0.6", lw=0.6)
    bottom.axhline(0, color="0.6", lw=0.6)
    top.set_ylabel("flux density [mT]")
    bottom.set_ylabel("residual [mT]")
    bottom.set_xlabel("angle [deg] (counter-clockwise from +x)")
    top.set_title(args.title)
    top.legend(fontsize=8, ncol=3)
    bottom.legend(fontsize=7, ncol=2)
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    # Atomic: a half-written PNG never replaces a good one.
    tmp = f"{args.output}.tmp{os.getpid()}.png"
    fig.savefig(tmp, dpi=120)
    os.replace(tmp, args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
