#!/usr/bin/env python3
"""The report of a finished magbrush run: PNG plots and index.md / index.html.

Called by `magbrush report CASE` (which checks the inputs and finds this script):

    report.py --case-name NAME --dem-dir RESULTS/dem --field-prefix RESULTS/fields/NAME_ --out RESULTS/report
              [--run-times RESULTS/run_times.csv] [--measured-flux report/measured_flux.csv]
              [--sleeve-radius R --drum-radius RD --drum-center X,Y]

Reads (what exists): dem/nip_profile.csv, nip_summary.csv, chain_inclination.csv,
brush_height.csv, nip_time_series.csv (the nip measurements), time_series.csv, the last snapshot in
dem/snapshots/, dem/dem.log (time per phase and force term, written by `magbrush run`),
<field-prefix>profile_sleeve.csv, dem/summary.csv (every key number with its standard error and
bound), <out>/case_resolved.txt and the run folder's variant.txt (the inputs and overrides).
The page is meant to decide from: every key number with ± its standard error, the inputs with
the resolved case linked, the averaging windows shaded on the time series, the nip bins of too
few contacts left out of the profiles (sparse_bins), the physical bound of each plot drawn. Writes every file atomically (tmp + rename). Needs numpy,
matplotlib (Agg) and h5py; exit status 3 when one is missing, 2 for unreadable inputs.
"""
import argparse
import csv
import glob
import html
import math
import os
import re
import sys

MU0 = 4e-7 * math.pi


# ------------------------------------------------------------------------------------------
# Reading

def read_csv(path):
    """Columns of a magbrush CSV by header name ('#' lines skipped); None when absent."""
    if not path or not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    if not rows:
        return None
    header, data = rows[0], rows[1:]
    cols = {}
    for i, name in enumerate(header):
        vals = []
        for r in data:
            try:
                vals.append(float(r[i]))
            except (ValueError, IndexError):
                vals.append(r[i] if i < len(r) else "")
        cols[name] = vals
    return cols


def read_summary(path):
    """nip_summary.csv as {key: (value, unit)}."""
    table = read_csv(path)
    if not table:
        return {}
    return {k: (v, u) for k, v, u in zip(table["key"], table["value"], table["unit"])}


def read_run_summary(path):
    """dem/summary.csv (every measurement's key numbers) as a list of row dicts; [] if absent."""
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        lines = [line for line in f if not line.startswith("#")]
    return list(csv.DictReader(lines))


def steady_state_rows(run_summary, supplied=True):
    """The steady-state verdict (the run's own: every tested mean drifts less than
    statistics.steady_drift between the halves of its averaging window), the drift of each
    tested mean, worst first, and what a failed test means: a trend (a drift beyond two of its
    standard errors: run longer) or a window too noisy to decide (average more samples).
    `supplied`: particles enter the scene (an inflow); without one the load in the scene only
    drains, so more samples must come from a deeper slab, not a longer run."""
    if not run_summary:
        return []
    by_key = {r["key"]: r for r in run_summary}
    verdict = by_key.get("steady_state")
    tested, states = [], []
    for r in run_summary:
        try:
            drift = float(r["drift"])
        except ValueError:
            continue
        if math.isfinite(drift):
            # A state value (the beads the scene holds) decides the verdict with the forces'
            # trends (dem/run_summary.h): it is named first.
            (states if r.get("state") == "1" else tested).append((abs(drift), drift, r["key"]))
    if verdict is None or not (tested or states):
        return []
    tested.sort(reverse=True)
    reached = verdict["value"] == "1"
    # Signed: + still rising, − still falling (or draining).
    worst = ", ".join(f"{k} {100 * d:+.1f} %" for _, d, k in states + tested[:4])
    trend = by_key.get("significant_drift", {}).get("value")
    try:
        resolution = float(by_key.get("drift_resolution", {}).get("value", "nan"))
    except ValueError:
        resolution = float("nan")
    if reached:
        state = "reached"
    elif trend == "0":
        state = "undecided: the drifts are within their noise"
    else:
        state = "NOT reached: still drifting"
    note = f"drift: {worst}"
    if math.isfinite(resolution):
        note += f"; this window resolves drifts down to {100 * resolution:.1f} % (2 standard errors)"
        tolerance = drift_tolerance(verdict["meaning"])
        if reached and states and math.isfinite(tolerance) and resolution > tolerance:
            note += f" — so the forces show no trend beyond that, not a {100 * tolerance:g} % certainty"
        if not reached and trend == "0" and math.isfinite(tolerance) and resolution > tolerance:
            # Block standard errors fall as 1/sqrt(window): (resolution / tolerance)² windows.
            how = ("a longer run, or a deeper slab" if supplied else
                   "a deeper slab: nothing is supplied, the load drains, so a longer run adds its trend")
            note += (f"; to decide at {100 * tolerance:g} % average over ~{(resolution / tolerance) ** 2:.1f}× "
                     f"this window ({how})")
    return [("steady state", state, verdict["meaning"], note)]


def drift_tolerance(meaning):
    """The steady-state tolerance from the verdict's text ("... drift < 2 % between ..."), as a
    fraction; nan when the text does not state it."""
    m = re.search(r"drift < ([0-9.]+) %", meaning)
    return float(m.group(1)) / 100.0 if m else float("nan")


def window_budget_row(nip_series):
    """The nip window's bead budget (nip_time_series.csv): inside(end) = inside(start) + entered
    − left holds by construction of the crossing counts, unless particles are created or removed
    inside the window (an inflow or outflow within nip.chain_half_angle of the gap centre):
    then the crossings are not the flux through the nip, and the row says so."""
    first, last = 0, len(nip_series["time_s"]) - 1
    inside0, inside1 = int(nip_series["in_window"][first]), int(nip_series["in_window"][last])
    entered, left = int(nip_series["entered"][last]), int(nip_series["left"][last])
    holds = inside1 == inside0 + entered - left
    return ("beads through the nip window", f"entered {entered}, left {left}, inside {inside0} → {inside1}",
            "inside(end) = inside(start) + entered − left",
            "holds" if holds else
            f"does NOT hold (off by {inside1 - inside0 - entered + left:+d}): particles appear or vanish inside "
            "the window, so its crossings are not the flux through the nip; keep the inflow and outflow "
            "outside ±nip.chain_half_angle")


def budget_row(flow):
    """Particles in, out and present for a fed scene (flow_report.csv): present = initial + in − out."""
    if not flow or not flow.get("time_s"):
        return None
    first, last = 0, len(flow["time_s"]) - 1
    initial = int(flow["present"][first]) - int(flow["in"][first]) + int(flow["out"][first])
    closes = int(flow["present"][last]) == initial + int(flow["in"][last]) - int(flow["out"][last])
    return ("particles: initial, in, out, present",
            f"{initial}, +{int(flow['in'][last])}, −{int(flow['out'][last])}, {int(flow['present'][last])}",
            "present = initial + in − out (inflow and outflow, flow_report.csv)",
            "conserved" if closes else "NOT conserved")


def sump_row(flow):
    """A finite, closed sump (inflow.sump_mass): the developer in the scene plus the sump's stock
    must stay constant, whatever leaves returning to the sump."""
    if not flow or not flow.get("sump_mass_kg") or not flow.get("time_s"):
        return None
    stock = [float(s) for s in flow["sump_mass_kg"]]
    # (The engine writes nan without a finite sump: inflow.supply fixed, or an unlimited sump.)
    if not all(math.isfinite(s) for s in stock) or stock[0] == 0.0 and stock[-1] == 0.0:
        return None
    totals = [float(p) + s for p, s in zip(flow["present_mass_kg"], stock)]
    if totals[0] <= 0.0:
        return None
    worst = max(abs(t - totals[0]) for t in totals) / totals[0]
    return ("developer in the scene + the sump", f"{totals[0]:.6g} kg → {totals[-1]:.6g} kg",
            "a finite, closed sump: the inflow draws on it, the outflow returns to it",
            # the CSV keeps 9 significant digits: a sum of two rounded values is good to ~1e-8
            f"conserved (worst {worst:.1e})" if worst < 2e-8 else f"NOT conserved (worst {worst:.1e})")


def read_phase_times(log_path):
    """The engine's 'time per phase' table from the DEM log: [(name, seconds, percent)]."""
    if not log_path or not os.path.exists(log_path):
        return []
    rows, inside = [], False
    with open(log_path, errors="replace") as f:
        for line in f:
            if line.startswith("time per phase"):
                rows, inside = [], True
                continue
            if inside:
                m = re.match(r"\s+(.+?)\s+([0-9.eE+-]+) s\s+([0-9.]+) %", line)
                if not m:
                    inside = False
                    continue
                rows.append((m.group(1), float(m.group(2)), float(m.group(3))))
    return rows


def read_log_line(log_path, prefix):
    if not log_path or not os.path.exists(log_path):
        return None
    found = None
    with open(log_path, errors="replace") as f:
        for line in f:
            if line.startswith(prefix):
                found = line.strip()
    return found


def drum_friction(log_path):
    """The carrier-drum friction coefficient the engine used (its log's contact table:
    "carrier–wall:drum ... mu 0.35"); None when the log does not state it."""
    line = read_log_line(log_path, "  carrier–wall:drum")
    m = re.search(r"\bmu ([0-9.eE+-]+)", line or "")
    return float(m.group(1)) if m else None


TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9}


def averaging_windows(dem_dir, resolved_path):
    """[(label, t_from [s])] of the averaging windows of the measurements this run made (their
    files exist), from the resolved case (case_resolved.txt: "nip.average_from = 25 ms")."""
    starts = {}
    if resolved_path and os.path.exists(resolved_path):
        with open(resolved_path) as f:
            for line in f:
                m = re.match(r"(\w+)\.average_from\s+=\s+([0-9.eE+-]+)\s*(\S+)", line)
                if m and m.group(3) in TIME_UNITS:
                    starts[m.group(1)] = float(m.group(2)) * TIME_UNITS[m.group(3)]
    windows = []
    for label, section, files in (("nip", "nip", ("nip_profile.csv",)),
                                  ("toner development", "development", ("toner_development.csv",)),
                                  ("DMA", "dma", ("developer_mass_per_area.csv",)),
                                  ("flow report", "flow_report", ("flow_report.csv",))):
        if section in starts and any(os.path.exists(os.path.join(dem_dir, f)) for f in files):
            windows.append((label, starts[section]))
    return windows


def last_snapshot(dem_dir):
    files = sorted(glob.glob(os.path.join(dem_dir, "snapshots", "particles_*.h5")))
    return files[-1] if files else None


# ------------------------------------------------------------------------------------------
# Writing

def save(fig, path):
    tmp = path + ".tmp"
    fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    os.replace(tmp, path)


def write_text(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def fmt(v, digits=4):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:.{digits}g}"


# ------------------------------------------------------------------------------------------
# Plots

def sparse_bins(profile, samples):
    """The bins of the nip profile averaged over too few contacts to plot as a mean: fewer
    contact samples than a tenth of the window's samples (less than one touching bead every ten
    samples). An edge bin touched once holds one bead's force — 175 uN where the profile's
    beads carry 1-10 uN — and would set the plot's scale. [bool per bin]; none without counts."""
    counts = profile.get("contact_samples")
    if not counts:
        return [False] * len(profile["x_mm"])
    threshold = max(2.0, 0.1 * samples) if samples == samples and samples > 0 else 2.0
    return [0 < c < threshold for c in counts]


def nip_plots(plt, profile, out, relative_speed, samples=float("nan"), friction=None, magnetic_pressure=None):
    """Kawamoto Fig. 17-20 from nip_profile.csv; returns the PNG names written. Bins with too
    few contacts (sparse_bins) are drawn as grey crosses, out of the curves and the scale; the
    physical bound or scale of each plot is drawn as a dashed line: the relative surface speed
    (slip), the Coulomb bound of the bead-drum friction coefficient (tangential/normal: no
    contact holds more), B^2/2mu0 at the gap centre (pressure)."""
    x = profile["x_mm"]
    written = []
    sparse = sparse_bins(profile, samples)
    threshold = max(2.0, 0.1 * samples) if samples == samples and samples > 0 else 2.0

    def one(name, ylabel, series, title, hline=None, hlabel=None):
        fig, ax = plt.subplots(figsize=(7, 4))
        marked = False
        for label, y, style in series:
            kept = [v if not sp else float("nan") for v, sp in zip(y, sparse)]
            ax.plot(x, kept, style, label=label)
            xs = [xi for xi, v, sp in zip(x, y, sparse) if sp and v == v]
            if xs:
                # Greyed, on the axis: where the bin is, not its value (it would set the scale).
                ax.plot(xs, [0.0] * len(xs), "x", color="0.6",
                        label=None if marked else f"bins of fewer than {threshold:.0f} contact samples (not plotted)")
                marked = True
        if hline is not None:
            ax.axhline(hline, color="0.4", ls="--", lw=1, label=hlabel)
        ax.axvline(0, color="0.7", lw=0.8)
        ax.set_xlabel("x along the nip from the gap centre [mm] (positive downstream)")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        save(fig, os.path.join(out, name))
        plt.close(fig)
        written.append(name)

    slip_series = [("contact points of the beads touching the drum (time average)", profile["slip_speed_m_s"], "o-")]
    if "chain_speed_m_s" in profile:  # profiles written before the chain speed lack it
        slip_series.append(("centres of those beads (the chain's end, rolling included)", profile["chain_speed_m_s"], "s-"))
    one("nip_slip.png", "slip speed [m/s]", slip_series,
        "Slip speed of the beads touching the drum (cf. Kawamoto Fig. 17)", relative_speed,
        f"relative surface speed {relative_speed:.4g} m/s" if relative_speed is not None else None)
    top = max((v for v in profile["normal_pressure_Pa"] if v == v), default=0.0)
    show_pm = magnetic_pressure is not None and magnetic_pressure == magnetic_pressure and 0 < top and \
        magnetic_pressure < 3 * top
    one("nip_pressure.png", "pressure on the drum [kPa]",
        [("normal", [v / 1e3 for v in profile["normal_pressure_Pa"]], "o-"),
         ("tangential", [v / 1e3 for v in profile["tangential_pressure_Pa"]], "s-")],
        "Normal and tangential pressure on the drum (cf. Fig. 18)"
        + ("" if show_pm or magnetic_pressure is None or magnetic_pressure != magnetic_pressure
           else f"\nB²/2μ0 = {magnetic_pressure / 1e3:.3g} kPa at the gap centre (off the scale)"),
        magnetic_pressure / 1e3 if show_pm else None,
        f"B²/2μ0 at the gap centre {magnetic_pressure / 1e3:.3g} kPa" if show_pm else None)
    written.append(mirrored_pressure_plot(plt, profile, out))
    mu = friction if friction is not None else 0.35
    one("nip_ratio.png", "tangential / normal", [("tangential / normal pressure", profile["tangential_over_normal"], "o-")],
        "Ratio of tangential to normal pressure", mu,
        f"bead-drum friction coefficient {mu:.3g}: the Coulomb bound" + ("" if friction is not None else " (assumed)"))
    one("nip_density.png", "touching beads [1/mm²]", [("beads touching the drum", profile["density_per_mm2"], "o-")],
        "Density of the beads touching the drum (cf. Fig. 19)")
    one("nip_force_per_bead.png", "normal force per touching bead [µN]",
        [("mean normal force per bead", [v * 1e6 for v in profile["normal_force_per_bead_N"]], "o-")],
        "Differential force: normal force per touching bead (cf. Fig. 20)")
    return written


def mirrored_pressure_plot(plt, profile, out):
    """The normal pressure and the touching density against the distance from the gap centre,
    the upstream half folded onto the downstream one: a symmetric nip draws one curve twice."""
    x = profile["x_mm"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, scale, label in ((axes[0], "normal_pressure_Pa", 1e-3, "normal pressure [kPa]"),
                                  (axes[1], "density_per_mm2", 1.0, "touching beads [1/mm²]")):
        up = [(-xi, v * scale) for xi, v in zip(x, profile[key]) if xi <= 0]
        down = [(xi, v * scale) for xi, v in zip(x, profile[key]) if xi >= 0]
        ax.plot([a for a, _ in up], [b for _, b in up], "o-", label="before the centre (x < 0), mirrored")
        ax.plot([a for a, _ in down], [b for _, b in down], "s-", label="after the centre (x > 0)")
        ax.set_xlabel("|x| from the gap centre [mm]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("The nip folded about the gap centre (Kawamoto: almost symmetric)")
    save(fig, os.path.join(out, "nip_pressure_mirrored.png"))
    plt.close(fig)
    return "nip_pressure_mirrored.png"


def chain_plot(plt, chains, flux, out):
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(chains["theta_deg"], chains["inclination_deg"], "o-", label="chains (principal contact direction)")
    if flux:
        # Field-line inclination from the sleeve normal: atan(Bt/Bn), folded into (-90, 90].
        ang = [a if a <= 180 else a - 360 for a in flux["angle_deg"]]
        span = max(abs(t) for t in chains["theta_deg"]) if chains["theta_deg"] else 30
        s = flux["sense"]
        pts = sorted((s * (a - flux["drum_deg"]), s * math.degrees(math.atan(bt / bn)) if bn != 0 else 90.0)
                     for a, bn, bt in zip(ang, flux["Bn"], flux["Bt"]) if abs(a - flux["drum_deg"]) <= span)
        xs, ys = [], []
        for k, q in enumerate(pts):
            if k and abs(q[1] - pts[k - 1][1]) > 90:  # the field turns through the tangent: break the line
                xs.append(float("nan"))
                ys.append(float("nan"))
            xs.append(q[0])
            ys.append(q[1])
        if pts:
            ax.plot(xs, ys, "--", color="0.4", label="flux lines at the sleeve surface (atan Bt/Bn)")
    ax.axvline(0, color="0.7", lw=0.8)
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xlabel("sleeve angle from the gap centre [deg] (positive downstream)")
    ax.set_ylabel("inclination from the sleeve normal [deg]\n(> 0: leaning downstream)")
    ax.set_title("Chain inclination before and after the gap")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, os.path.join(out, "chain_inclination.png"))
    plt.close(fig)
    return "chain_inclination.png"


def brush_height_plot(plt, brush, out):
    """The brush's tip height against the gap along the sleeve (where the two meet, the brush
    presses the drum), and the developer per sleeve area under it (a pile before the gap shows
    as mass piling up where the tips already fill the gap)."""
    theta = brush["theta_deg"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    top.plot(theta, [g * 1e3 for g in brush["gap_mm"]], "-", color="0.3", label="gap (sleeve to drum along the radius)")
    top.plot(theta, [h * 1e3 for h in brush["tip_height_mm"]], "o-", label="brush tip (highest bead top, time mean)")
    finite = [g * 1e3 for g in brush["gap_mm"] if isinstance(g, float) and math.isfinite(g)]
    if finite:
        top.set_ylim(0, min(max(finite), 3 * min(finite)))
    top.set_ylabel("height above the sleeve [um]")
    top.set_title("Brush height along the sleeve")
    bottom.plot(theta, brush["mass_per_area_kg_m2"], "s-", color="tab:green")
    bottom.set_ylabel("carriers per sleeve area [kg/m²]")
    bottom.set_xlabel("sleeve angle from the gap centre [deg] (positive downstream)")
    for ax in (top, bottom):
        ax.axvline(0, color="0.7", lw=0.8)
        ax.grid(alpha=0.3)
    top.legend(fontsize=8)
    save(fig, os.path.join(out, "brush_height.png"))
    plt.close(fig)
    return "brush_height.png"


def flux_plot(plt, flux, measured, out, case_name):
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(flux["angle_deg"], [b * 1e3 for b in flux["Bn"]], "-", color="tab:blue", label="Bn computed")
    ax.plot(flux["angle_deg"], [b * 1e3 for b in flux["Bt"]], "-", color="tab:orange", label="Bt computed")
    if measured:
        ax.plot(measured["angle_deg"], measured["Bn_mT"], ".", ms=3, color="tab:blue", label="Bn measured")
        if "Bt_mT" in measured:
            ax.plot(measured["angle_deg"], measured["Bt_mT"], ".", ms=3, color="tab:orange", label="Bt measured")
    ax.axvline(flux["drum_deg"] % 360, color="0.5", ls="--", lw=1, label="drum (gap centre)")
    ax.axhline(0, color="0.7", lw=0.6)
    ax.set_xlabel("angle [deg] (counter-clockwise from +x)")
    ax.set_ylabel("flux density at the sleeve surface [mT]")
    ax.set_title(f"Sleeve flux profile, case {case_name}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, ncol=3)
    save(fig, os.path.join(out, "flux_profile.png"))
    plt.close(fig)
    return "flux_profile.png"


def snapshot_plot(plt, h5py, np, snap, geometry, out):
    """The brush in the nip, unrolled: arc length along the sleeve from the gap centre against
    the height above the sleeve, one slice of the slab (two mean diameters deep) so that single
    chains can be seen; beads drawn to scale, coloured by speed; the drum surface as a line."""
    from matplotlib.collections import EllipseCollection
    with h5py.File(snap, "r") as f:
        pos = np.array(f["position"])
        vel = np.array(f["velocity"])
        rad = np.array(f["radius"]).ravel()
        t = float(f.attrs["time"])
    speed = np.linalg.norm(vel, axis=1)
    rs, rd, (cx, cy), sense = geometry
    if rs <= 0 or rd <= 0:
        return None, t
    d = math.hypot(cx, cy)
    phi0 = math.atan2(cy, cx)
    r = np.hypot(pos[:, 0], pos[:, 1])
    theta = sense * (np.arctan2(pos[:, 1], pos[:, 0]) - phi0)
    theta = (theta + np.pi) % (2 * np.pi) - np.pi
    s_arc = rs * theta                     # arc length on the sleeve from the gap centre
    h = r - rs                             # height above the sleeve surface
    zc = 0.5 * (pos[:, 2].min() + pos[:, 2].max())
    depth = 2.0 * 2.0 * rad.mean()
    sel = (np.abs(pos[:, 2] - zc) < 0.5 * depth) & (np.abs(s_arc) < 4e-3) & (h < 1.5e-3)
    fig, ax = plt.subplots(figsize=(11, 3.6))
    offsets = np.column_stack([s_arc[sel] * 1e3, h[sel] * 1e3])
    widths = 2 * rad[sel] * 1e3
    coll = EllipseCollection(widths, widths, np.zeros_like(widths), units="xy", offsets=offsets,
                             transOffset=ax.transData, cmap="viridis", edgecolors="k", linewidths=0.2)
    coll.set_array(speed[sel])
    ax.add_collection(coll)
    fig.colorbar(coll, ax=ax, label="bead speed [m/s]", pad=0.01, shrink=0.7)
    # Drum surface: along the ray at sleeve angle θ, the distance ρ where |ρ e(θ) − C| = Rd.
    th = np.linspace(-4e-3 / rs, 4e-3 / rs, 400)
    ex = np.cos(phi0 + sense * th)
    ey = np.sin(phi0 + sense * th)
    b = ex * cx + ey * cy
    rho = b - np.sqrt(np.maximum(b * b - (d * d - rd * rd), 0.0))
    ax.plot(rs * th * 1e3, (rho - rs) * 1e3, "-", color="tab:red", lw=1.5, label="drum surface")
    ax.axhline(0, color="k", lw=1.5, label="sleeve surface")
    ax.set_xlim(-4, 4)
    ax.set_ylim(-0.05, 1.0)
    ax.set_aspect("equal")
    ax.set_xlabel("arc length along the sleeve from the gap centre [mm] (sleeve moves to the right)")
    ax.set_ylabel("height above the sleeve [mm]")
    ax.set_title(f"Brush in the nip at t = {t * 1e3:.3f} ms: a slice {depth * 1e6:.0f} µm deep of the slab "
                 f"({int(sel.sum())} beads)", fontsize=9)
    ax.legend(fontsize=8, loc="upper right")
    save(fig, os.path.join(out, "brush_snapshot.png"))
    plt.close(fig)
    return "brush_snapshot.png", t


def series_plot(plt, series, nip_series, out, windows=()):
    """Energies, wall loads and the nip's bead budget against time, each averaging window
    shaded: windows = [(label, t_from [s])], each running to the end of the run."""
    panels = 3 if nip_series else 2
    fig, axes = plt.subplots(panels, 1, figsize=(8, 3 * panels), sharex=True)
    t = [v * 1e3 for v in series["time"]]
    axes[0].semilogy(t, [max(v, 1e-30) for v in series["kinetic_energy"]], label="kinetic (translational)")
    axes[0].semilogy(t, [max(v, 1e-30) for v in series["rotational_energy"]], label="rotational")
    axes[0].set_ylabel("energy [J]")
    axes[0].legend(fontsize=8)
    ax2 = axes[0].twinx()
    ax2.plot(t, series["particle_contacts"], color="tab:green", lw=0.8, label="particle contacts")
    ax2.set_ylabel("contacts", color="tab:green")
    for key in series:
        m = re.match(r"(.+)_F([xy])$", key)
        if m:
            axes[1].plot(t, series[key], lw=0.9, label=f"{m.group(1)} F{m.group(2)}")
    axes[1].set_ylabel("wall load [N]")
    axes[1].legend(fontsize=8, ncol=2)
    if nip_series:
        tn = [v * 1e3 for v in nip_series["time_s"]]
        axes[2].plot(tn, nip_series["in_window"], label="beads in the nip window")
        axes[2].plot(tn, nip_series["entered"], label="entered (upstream edge)")
        axes[2].plot(tn, nip_series["left"], label="left (downstream edge)")
        axes[2].plot(tn, nip_series["drum_touching"], label="touching the drum")
        axes[2].set_ylabel("beads")
        axes[2].legend(fontsize=8, ncol=2)
    axes[-1].set_xlabel("time [ms] (t = 0: walls start turning)")
    end = t[-1] if t else 0.0
    colours = ("tab:blue", "tab:orange", "tab:green", "tab:purple")
    for k, (label, t_from) in enumerate(windows):
        for i, ax in enumerate(axes):
            ax.axvspan(t_from * 1e3, end, color=colours[k % len(colours)], alpha=0.07,
                       label=f"{label} averaged from {t_from * 1e3:.3g} ms" if i == len(axes) - 1 else None)
    if windows:
        axes[-1].legend(fontsize=8, ncol=2)
    for ax in axes:
        ax.grid(alpha=0.3)
    save(fig, os.path.join(out, "time_series.png"))
    plt.close(fig)
    return "time_series.png"


def averaging_start(path):
    """The averaging window's start [s] that toner_development.csv states in its first line
    (0 when it states none: files of earlier versions, which held only the window's rows)."""
    with open(path) as f:
        m = re.search(r"from t = (\S+) s", f.readline())
    return float(m.group(1)) if m else 0.0


def window_halves(t, values, t_from):
    """The samples (t, value) from t_from on, without NaN, and the means of their two halves by
    count (the steady-state test compares those; with fewer than 4 samples: no halves)."""
    window = [(ti, v) for ti, v in zip(t, values) if ti >= t_from and v == v]
    half = len(window) // 2
    if half < 2:
        return window, []
    return window, [(part[0][0], part[-1][0], sum(v for _, v in part) / len(part))
                    for part in (window[:half], window[half:])]


def period_halves(t_start, t_end, values):
    """The whole image periods' halves as the steady-state test takes them (the older n // 2
    periods and the newer rest): (first start, last end, mean) each; none with fewer than 2."""
    n = len(values)
    if n < 2:
        return []
    cut = n // 2
    return [(t_start[a], t_end[b - 1], sum(values[a:b]) / (b - a)) for a, b in ((0, cut), (cut, n))]


def development_plot(plt, dem_dir, run_summary, out):
    """TMA and fog against time (toner_development.csv), the averaging window shaded, its mean
    with the standard error, the means of its two halves (the steady-state test compares them)
    and the neutralisation bound. None when the run measured no toner development."""
    path = os.path.join(dem_dir, "toner_development.csv")
    dev = read_csv(path)
    if not dev or not dev.get("time_s"):
        return None
    t_from = averaging_start(path)
    rows = {r["key"]: r for r in run_summary}

    def number(key, column="value"):
        try:
            return float(rows[key][column])
        except (KeyError, ValueError):
            return float("nan")

    t = [v * 1e3 for v in dev["time_s"]]
    # Over whole image periods (development.average_over: image_periods) the means are those
    # of the periods past the line; the window's samples repeat with the image.
    periods = read_csv(os.path.join(dem_dir, "toner_developed_periods.csv"))
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, dev["tma_kg_per_m2"], lw=0.9, alpha=0.5 if periods is not None else 1.0,
            label="TMA in the window (image strips)")
    ax.plot(t, dev["fog_kg_per_m2"], lw=0.9, color="tab:gray", label="fog (dark strips)")
    ax.axvspan(t_from * 1e3, t[-1], color="tab:blue", alpha=0.08, label="averaging window")
    mean, se = number("tma_kg_per_m2"), number("tma_kg_per_m2", "standard_error")
    window, halves = window_halves(t, dev["tma_kg_per_m2"], t_from * 1e3)
    if periods is not None:
        starts = [v * 1e3 for v in periods.get("t_start_s", [])]
        ends = [v * 1e3 for v in periods.get("t_end_s", [])]
        values = periods.get("tma_kg_per_m2", [])
        if values:
            ax.hlines(values, starts, ends, color="tab:green", lw=3,
                      label="TMA of each whole image period past the line")
        halves = period_halves(starts, ends, values)
        window = list(zip(starts, values)) + list(zip(ends[-1:], values[-1:]))
    if mean == mean and window:
        what = f" over {len(periods.get('tma_kg_per_m2', []))} periods" if periods is not None else ""
        ax.hlines(mean, window[0][0], window[-1][0], color="tab:blue", lw=2,
                  label=f"mean{what} {mean:.3g} ± {se:.2g} kg/m²")
        for begin, end, value in halves:
            ax.hlines(value, begin, end, color="tab:orange", lw=1.5, ls="--")
        if halves:
            ax.plot([], [], color="tab:orange", ls="--",
                    label=f"halves (drift {100 * number('tma_kg_per_m2', 'drift'):+.1f} %)")
    bound = number("tma_kg_per_m2_bound")
    top = max((v for v in dev["tma_kg_per_m2"] if v == v), default=0.0)
    if bound == bound and top > 0 and bound < 5 * top:
        ax.axhline(bound, color="tab:red", ls=":", label="neutralisation bound")
    elif bound == bound:
        ax.set_title(f"neutralisation bound {bound:.3g} kg/m² (off the scale)", fontsize=9)
    steady = number("steady_state")
    verdict = "steady" if steady == 1 else "not steady" if steady == 0 else "steady state not tested"
    ax.text(0.01, 0.97, f"run: {verdict}", transform=ax.transAxes, va="top", fontsize=9)
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("toner mass per area [kg/m²]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    save(fig, os.path.join(out, "toner_development.png"))
    plt.close(fig)
    return "toner_development.png"


def developed_profile_plot(plt, dem_dir, out):
    """The developed profile across one image period (toner_developed_profile.csv): toner mass
    per area against the position from the exposed strip's centre, the exposed strip shaded.
    None when the run did not average over image periods or closed none."""
    path = os.path.join(dem_dir, "toner_developed_profile.csv")
    prof = read_csv(path)
    if not prof or not prof.get("position_mm"):
        return None
    with open(path) as f:
        header = f.readline().lstrip("# ").strip()
    x, y, exposed = prof["position_mm"], prof["toner_mass_per_area_kg_per_m2"], prof["exposed"]
    if not any(v == v for v in y):
        return None
    fig, ax = plt.subplots(figsize=(8, 3.5))
    width = (x[1] - x[0]) if len(x) > 1 else 1.0
    ax.bar(x, [v if v == v else 0.0 for v in y], width=width * 0.95,
           color=["tab:blue" if e == 1 else "tab:gray" for e in exposed])
    lit = [xi for xi, e in zip(x, exposed) if e == 1]
    if lit:
        ax.axvspan(min(lit) - width / 2, max(lit) + width / 2, color="tab:blue", alpha=0.08,
                   label="exposed strip (image)")
        ax.legend(fontsize=8, loc="upper right")
    ax.set_title(header.split(";")[0], fontsize=8)
    ax.set_xlabel("position from the exposed strip's centre [mm]")
    ax.set_ylabel("toner mass per area [kg/m²]")
    ax.grid(alpha=0.3)
    save(fig, os.path.join(out, "toner_developed_profile.png"))
    plt.close(fig)
    return "toner_developed_profile.png"


# ------------------------------------------------------------------------------------------
# Key numbers and the index

def symmetry_rows(run_summary):
    """How symmetric the nip is about the gap centre (dem/measurements/nip_asymmetry.h), with the
    standard errors of dem/summary.csv: the pressure's centroid against its spread, and the
    pressure and the touching beads before the centre over after it (Kawamoto: almost symmetric,
    the touching density slightly higher at the outlet)."""
    by_key = {r["key"]: r for r in run_summary or []}

    def get(key):
        r = by_key.get(key)
        if r is None:
            return float("nan"), float("nan")
        try:
            return float(r["value"]), float(r["standard_error"])
        except ValueError:
            return float("nan"), float("nan")

    c, c_se = get("pressure_centroid_m")
    w, w_se = get("pressure_spread_m")
    if not math.isfinite(c):
        return []
    p, p_se = get("pressure_upstream_over_downstream")
    t, t_se = get("touching_upstream_over_downstream")
    tc, tc_se = get("touching_centroid_m")
    side = "upstream" if c < 0 else "downstream"
    return [
        ("normal pressure: centroid / spread", f"{fmt(c * 1e3, 3)} ± {fmt(c_se * 1e3, 2)} mm / "
         f"{fmt(w * 1e3, 3)} ± {fmt(w_se * 1e3, 2)} mm",
         "Kawamoto: almost symmetric about the gap centre (centroid ≈ 0)",
         f"centroid {fmt(abs(c) / w if w else float('nan'), 2)} × the spread, {side}"),
        ("normal pressure before / after the gap centre", f"{fmt(p, 3)} ± {fmt(p_se, 2)}", "1: symmetric", ""),
        ("touching beads: centroid; before / after the centre",
         f"{fmt(tc * 1e3, 3)} ± {fmt(tc_se * 1e3, 2)} mm; {fmt(t, 3)} ± {fmt(t_se, 2)}",
         "Kawamoto: almost symmetric, slightly more at the outlet (ratio < 1)", ""),
    ]


def with_error(run_summary, key, value, scale=1.0, digits=4):
    """"value ± standard error" of a key of dem/summary.csv (the value as given, the error
    scaled like it); the value alone when the run gives no error for it."""
    se = float("nan")
    for r in run_summary or []:
        if r.get("key") == key:
            try:
                se = float(r.get("standard_error", "nan"))
            except ValueError:
                pass
    return fmt(value * scale, digits) + (f" ± {fmt(se * scale, 2)}" if math.isfinite(se) else "")


def key_numbers(summary, nip_series, series, flux, run_summary=None, flow=None):
    """[(what, value, reference, verdict)] for the summary table."""
    rows = steady_state_rows(run_summary, supplied=flow is not None)

    def val(key):
        v = summary.get(key, (float("nan"), ""))[0]
        return v if isinstance(v, float) else float("nan")

    def err(key, summary_key, scale=1.0, digits=4):
        return with_error(run_summary, summary_key, val(key), scale, digits)

    samples = val("samples") if summary else float("nan")
    if summary and not (math.isfinite(samples) and samples > 0):
        # Nothing was averaged (the run ended before nip.average_from): no number is a mean
        # of the nip, so none is printed.
        rows.append(("nip profile", "no samples in the averaging window",
                     "the run ended before nip.average_from, or within one nip.sample_interval of it",
                     "no means to report"))
    elif summary:
        rel = val("relative_surface_speed")
        slip = val("slip_at_gap_centre")
        rows.append(("slip speed at the gap centre", f"{err('slip_at_gap_centre', 'slip_at_gap_centre_m_s')} m/s (bead spread {fmt(val('slip_std_at_gap_centre'), 2)})",
                     f"relative surface speed {fmt(rel)} m/s (Kawamoto: equal)",
                     f"{fmt(slip / rel if rel else float('nan'), 3)} of it"))
        chain = val("chain_speed_at_gap_centre")
        if math.isfinite(chain):
            rows.append(("chain speed over the drum at the gap centre", f"{err('chain_speed_at_gap_centre', 'chain_speed_at_gap_centre_m_s')} m/s (bead centres, rolling included)",
                         f"relative surface speed {fmt(rel)} m/s (Kawamoto: equal)",
                         f"{fmt(chain / rel if rel else float('nan'), 3)} of it"))
        b = val("gap_centre_field")
        if not math.isfinite(b) and flux:
            # The field at the sleeve surface facing the drum, from the sleeve profile.
            ang = flux["drum_deg"] % 360
            k = min(range(len(flux["angle_deg"])), key=lambda i: abs(flux["angle_deg"][i] - ang))
            b = math.hypot(flux["Bn"][k], flux["Bt"][k])
        pm = b * b / (2 * MU0) if math.isfinite(b) else float("nan")
        peak = val("peak_normal_pressure")
        rows.append(("peak normal pressure on the drum", f"{err('peak_normal_pressure', 'peak_normal_pressure_Pa', 1e-3)} kPa",
                     f"B²/2μ0 = {fmt(pm / 1e3)} kPa at B = {fmt(b * 1e3)} mT (gap centre)",
                     f"{fmt(peak / pm if pm else float('nan'), 3)} × B²/2μ0"))
        rows.append(("normal pressure at the gap centre",
                     f"{err('normal_pressure_at_gap_centre', 'normal_pressure_at_gap_centre_Pa', 1e-3)} kPa", "", ""))
        rows += symmetry_rows(run_summary)
        rows.append(("tangential / normal (whole nip)", err("tangential_over_normal", "tangential_over_normal", 1.0, 3),
                     "bead-drum friction coefficient 0.35 (Kawamoto: ≈ 0.35)", ""))
        rows.append(("touching-bead density at the gap centre",
                     f"{err('density_at_gap_centre', 'density_at_gap_centre_per_mm2')} /mm²",
                     "∝ 1/d² (Kawamoto Fig. 19)", ""))
        rows.append(("normal force on the drum per length",
                     f"{err('normal_force_per_length', 'normal_force_per_length_N_m')} N/m", "", ""))
        rows.append(("averaged over", f"{int(val('samples'))} samples, t = {fmt(val('t_from') * 1e3)} .. "
                     f"{fmt(val('t_to') * 1e3)} ms", "", ""))
    fed = budget_row(flow)
    if fed:
        rows.append(fed)
    closed = sump_row(flow)
    if closed:
        rows.append(closed)
    if nip_series and nip_series["time_s"]:
        first, last = 0, len(nip_series["time_s"]) - 1
        beads0, beads1 = int(nip_series["beads"][first]), int(nip_series["beads"][last])
        lost = int(nip_series["lost"][last])
        if not fed:  # a closed scene: every bead stays
            rows.append(("beads in the slab, start / end", f"{beads0} / {beads1}, lost {lost}",
                         "mass conservation: equal, none lost",
                         "conserved" if beads0 == beads1 and lost == 0 else "NOT conserved"))
        rows.append(window_budget_row(nip_series))
    elif series:
        rows.append(("simulated time", f"{fmt(series['time'][-1] * 1e3)} ms", "", ""))
    return rows


# The inputs a designer changes first, by key prefix, in the order shown (the whole resolved
# case is linked beside them).
MAIN_INPUTS = ("name", "sleeve.radius", "sleeve.rpm", "drum.radius", "drum.rpm", "drum.gap", "roller.poles.",
               "blades.", "electric.enabled", "electric.bias", "electric.image.", "populations.", "inflow.areal_mass",
               "dem.periodic_length", "dem.duration", "dem.time_step", "nip.average_from", "development.average_from",
               "dma.average_from", "flow_report.average_from")
MAIN_INPUT_LEAVES = (".angle", ".strength", ".gap", ".diameter", ".count", ".charge_to_mass", ".kind", ".period",
                     ".duty")


def inputs_table(resolved_path):
    """[(key, value)] of the main inputs in case_resolved.txt ("key = value" lines)."""
    if not resolved_path or not os.path.exists(resolved_path):
        return []
    rows = []
    with open(resolved_path) as f:
        for line in f:
            if line.startswith("#") or " = " not in line:
                continue
            key, value = (part.strip() for part in line.split(" = ", 1))
            for prefix in MAIN_INPUTS:
                if key == prefix or (prefix.endswith(".") and key.startswith(prefix) and
                                     key.endswith(MAIN_INPUT_LEAVES)):
                    rows.append((key, value))
                    break
    return rows


def read_overrides(run_dir):
    """The --set overrides of the run (variant.txt in its folder, "set key=value" lines)."""
    path = os.path.join(run_dir, "variant.txt")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return [line[4:].strip() for line in f if line.startswith("set ")]


def all_key_numbers(run_summary):
    """[(key, value ± se, unit, bound, meaning)] of every row of dem/summary.csv, the keys that
    are bounds (<key>_bound) shown beside the key they bound rather than as rows."""
    by_key = {r["key"]: r for r in run_summary or []}
    rows = []
    for r in run_summary or []:
        key = r["key"]
        if key.endswith("_bound") and key[: -len("_bound")] in by_key:
            continue
        try:
            value = float(r["value"])
        except (KeyError, ValueError):
            value = float("nan")
        bound = by_key.get(key + "_bound")
        rows.append((key, with_error(run_summary, key, value), r.get("unit", ""),
                     fmt(float(bound["value"])) if bound else "", r.get("meaning", "")))
    return rows


def design_section(run_dir, out):
    """The design of this case's poles (`magbrush design poles` writes <run folder>/design/): its
    profile against the target, its requirements met or missed, and a link to its own page
    (layout, binding constraints, sensitivities). None when the case has no design."""
    folder = os.path.join(run_dir, "design")
    page = os.path.join(folder, "index.html")
    if not os.path.exists(page):
        return None
    rows = []
    try:
        with open(os.path.join(folder, "design_requirements.csv"), newline="") as f:
            for r in csv.DictReader(line for line in f if not line.startswith("#")):
                fem = r.get("value_fem")
                rows.append((r["requirement"], f"{r['target']} ± {r['tolerance']} {r['unit']} ({r['kind']})",
                             r["value_ring"], "met" if r["met_ring"] == "1" else "MISSED",
                             fem or "", ("met" if r.get("met_fem") == "1" else "MISSED") if fem else ""))
    except (OSError, KeyError):
        pass
    image = os.path.join(folder, "design_profile.png")
    return {"page": os.path.relpath(page, out), "rows": rows,
            "image": os.path.relpath(image, out) if os.path.exists(image) else None}


def build_index(args, images, rows, run_times, phases, snapshot_time, dem_done, run_summary=None):
    links = []
    run_dir = os.path.dirname(os.path.normpath(args.dem_dir))
    resolved = os.path.join(args.out, "case_resolved.txt")
    inputs = inputs_table(resolved)
    overrides = read_overrides(run_dir)
    every_key = all_key_numbers(run_summary)
    xdmf = os.path.join(args.dem_dir, "particles.xdmf")
    if os.path.exists(xdmf):
        links.append(("particles (ParaView, time series)", os.path.relpath(xdmf, args.out)))
    for vtu in sorted(glob.glob(args.field_prefix + "*.pvtu")):
        links.append(("field " + os.path.basename(vtu), os.path.relpath(vtu, args.out)))
    for name in ("nip_profile.csv", "nip_summary.csv", "chain_inclination.csv", "brush_height.csv",
                 "nip_time_series.csv", "time_series.csv", "dem.log"):
        p = os.path.join(args.dem_dir, name)
        if os.path.exists(p):
            links.append((name, os.path.relpath(p, args.out)))
    prof = args.field_prefix + "profile_sleeve.csv"
    if os.path.exists(prof):
        links.append(("sleeve flux profile (CSV)", os.path.relpath(prof, args.out)))

    md = [f"# magbrush report: {args.case_name}", ""]
    md += ["## Key numbers", "", "| quantity | value | reference | |", "|---|---|---|---|"]
    md += [f"| {a} | {b} | {c} | {d} |" for a, b, c, d in rows]
    md.append("")
    md += ["## Inputs", "", "The whole resolved case: [case_resolved.txt](case_resolved.txt). Overrides: " +
           (", ".join(f"`{o}`" for o in overrides) if overrides else "none (the case as its file gives it)"
            if overrides is not None else "not recorded (run with `magbrush run` to keep them)"), ""]
    if inputs:
        md += ["| key | value |", "|---|---|"] + [f"| {k} | {v} |" for k, v in inputs] + [""]
    if every_key:
        md += ["## Every key number (dem/summary.csv)", "", "value ± standard error (block averages over the window)",
               "", "| key | value | unit | bound | meaning |", "|---|---|---|---|---|"]
        md += [f"| {k} | {v} | {u} | {b} | {m} |" for k, v, u, b, m in every_key]
        md.append("")
    if run_times:
        md += ["## Run time per stage", "", "| stage | wall time [s] |", "|---|---|"]
        md += [f"| {s} | {t:.1f} |" for s, t in run_times]
        md.append("")
    if phases:
        md += ["## DEM time per phase and force term", "", "| phase | wall time [s] | share |", "|---|---|---|"]
        md += [f"| {n} | {t:.2f} | {p:.1f} % |" for n, t, p in phases]
        md.append("")
    if dem_done:
        md += [f"DEM: `{dem_done}`", ""]
    design = design_section(run_dir, args.out)
    if design:
        md += ["## Design of the poles (magbrush design poles)", "",
               f"The design's own page, with the layout, the binding constraints and the sensitivities: "
               f"[{design['page']}]({design['page']}).", ""]
        if design["image"]:
            md += [f"![designed profile against the target]({design['image']})", ""]
        if design["rows"]:
            md += ["| requirement | target | exact ring | | FEM | |", "|---|---|---|---|---|---|"]
            md += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in design["rows"]]
            md.append("")
    md += ["## Plots", ""]
    md += [f"![{img}]({img})" for img in images]
    md += ["", "## Files (ParaView: open the .xdmf / .pvtu)", ""]
    md += [f"* [{a}]({b})" for a, b in links]
    md.append("")

    e = html.escape
    h = ["<!DOCTYPE html>", "<html><head><meta charset='utf-8'>", f"<title>magbrush report: {e(args.case_name)}</title>",
         "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;} table{border-collapse:collapse;}"
         " td,th{border:1px solid #bbb;padding:3px 8px;} img{max-width:100%;margin:6px 0;}</style></head><body>",
         f"<h1>magbrush report: {e(args.case_name)}</h1>", "<h2>Key numbers</h2>",
         "<p>value ± standard error (block averages over the averaging window); a number without ± has none "
         "in the run's summary (a single bin's value, or a ratio of sums).</p>",
         "<table><tr><th>quantity</th><th>value</th><th>reference</th><th></th></tr>"]
    h += [f"<tr><td>{e(a)}</td><td>{e(b)}</td><td>{e(c)}</td><td>{e(d)}</td></tr>" for a, b, c, d in rows]
    h.append("</table>")
    h.append("<h2>Inputs</h2><p>The whole resolved case: <a href='case_resolved.txt'>case_resolved.txt</a>. Overrides: " +
             (", ".join(f"<code>{e(o)}</code>" for o in overrides) if overrides else
              "none (the case as its file gives it)" if overrides is not None else
              "not recorded (run with <code>magbrush run</code> to keep them)") + "</p>")
    if inputs:
        h.append("<table><tr><th>key</th><th>value</th></tr>")
        h += [f"<tr><td>{e(k)}</td><td>{e(v)}</td></tr>" for k, v in inputs]
        h.append("</table>")
    if every_key:
        h += ["<h2>Every key number (dem/summary.csv)</h2><p>value ± standard error (block averages over the "
              "averaging window); a bound is the physical limit the key is judged against</p>",
              "<table><tr><th>key</th><th>value</th><th>unit</th><th>bound</th><th>meaning</th></tr>"]
        h += [f"<tr><td>{e(k)}</td><td>{e(v)}</td><td>{e(u)}</td><td>{e(b)}</td><td>{e(m)}</td></tr>"
              for k, v, u, b, m in every_key]
        h.append("</table>")
    if run_times:
        h += ["<h2>Run time per stage</h2><table><tr><th>stage</th><th>wall time [s]</th></tr>"]
        h += [f"<tr><td>{e(s)}</td><td>{t:.1f}</td></tr>" for s, t in run_times]
        h.append("</table>")
    if phases:
        h += ["<h2>DEM time per phase and force term</h2><table><tr><th>phase</th><th>wall time [s]</th>"
              "<th>share</th></tr>"]
        h += [f"<tr><td>{e(n)}</td><td>{t:.2f}</td><td>{p:.1f} %</td></tr>" for n, t, p in phases]
        h.append("</table>")
    if dem_done:
        h.append(f"<p>DEM: <code>{e(dem_done)}</code></p>")
    if design:
        h.append("<h2>Design of the poles (magbrush design poles)</h2><p>The design's own page, with the layout, "
                 f"the binding constraints and the sensitivities: <a href='{e(design['page'])}'>{e(design['page'])}</a></p>")
        if design["image"]:
            h.append(f"<p><img src='{e(design['image'])}' alt='designed profile against the target'></p>")
        if design["rows"]:
            h.append("<table><tr><th>requirement</th><th>target</th><th>exact ring</th><th></th><th>FEM</th><th></th></tr>")
            h += ["<tr>" + "".join(f"<td>{e(c)}</td>" for c in r) + "</tr>" for r in design["rows"]]
            h.append("</table>")
    h.append("<h2>Plots</h2>")
    h += [f"<p><a href='{e(img)}'><img src='{e(img)}' alt='{e(img)}'></a></p>" for img in images]
    h.append("<h2>Files (ParaView: open the .xdmf / .pvtu)</h2><ul>")
    h += [f"<li><a href='{e(b)}'>{e(a)}</a></li>" for a, b in links]
    h.append("</ul></body></html>")
    write_text(os.path.join(args.out, "index.md"), "\n".join(md))
    write_text(os.path.join(args.out, "index.html"), "\n".join(h) + "\n")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--case-name", required=True)
    p.add_argument("--dem-dir", required=True)
    p.add_argument("--field-prefix", required=True, help="<output.directory>/fields/<case>_ (the field stage's file prefix)")
    p.add_argument("--out", required=True)
    p.add_argument("--run-times")
    p.add_argument("--measured-flux")
    p.add_argument("--sleeve-radius", type=float, default=0.0)
    p.add_argument("--drum-radius", type=float, default=0.0)
    p.add_argument("--drum-center", default="0,0")
    p.add_argument("--sleeve-sense", type=float, default=1.0, help="+1: sleeve turns counter-clockwise, -1: clockwise")
    args = p.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        import numpy as np
        import h5py
    except ImportError as e:
        print(f"report.py: {e}: install python3-matplotlib, python3-numpy and python3-h5py", file=sys.stderr)
        return 3
    os.makedirs(args.out, exist_ok=True)
    cx, cy = (float(v) for v in args.drum_center.split(","))
    drum_deg = math.degrees(math.atan2(cy, cx)) if (cx or cy) else 0.0

    try:
        series = read_csv(os.path.join(args.dem_dir, "time_series.csv"))
        profile = read_csv(os.path.join(args.dem_dir, "nip_profile.csv"))
        summary = read_summary(os.path.join(args.dem_dir, "nip_summary.csv"))
        chains = read_csv(os.path.join(args.dem_dir, "chain_inclination.csv"))
        brush = read_csv(os.path.join(args.dem_dir, "brush_height.csv"))
        nip_series = read_csv(os.path.join(args.dem_dir, "nip_time_series.csv"))
        flux_raw = read_csv(args.field_prefix + "profile_sleeve.csv")
        measured = read_csv(args.measured_flux) if args.measured_flux else None
        run_times_table = read_csv(args.run_times) if args.run_times else None
    except (OSError, KeyError, IndexError) as e:
        print(f"report.py: cannot read the run's outputs: {e}", file=sys.stderr)
        return 2
    if series is None:
        print(f"report.py: {args.dem_dir}/time_series.csv is missing or empty", file=sys.stderr)
        return 2

    flux = None
    if flux_raw:
        # The chain plot turns the field direction into the nip frame: downstream is the way the
        # sleeve turns (sense +1: counter-clockwise, the profile's positive Bt).
        flux = {"angle_deg": flux_raw["angle_deg"], "Bn": flux_raw["Bn_T"], "Bt": flux_raw["Bt_T"],
                "drum_deg": drum_deg, "sense": args.sleeve_sense}

    images = []
    relative_speed = summary.get("relative_surface_speed", (None, ""))[0] if summary else None
    samples = summary.get("samples", (float("nan"), ""))[0] if summary else float("nan")
    magnetic_pressure = summary.get("magnetic_pressure", (None, ""))[0] if summary else None
    log = os.path.join(args.dem_dir, "dem.log")
    if profile:
        images += nip_plots(plt, profile, args.out, relative_speed, samples if isinstance(samples, float) else float("nan"),
                            drum_friction(log), magnetic_pressure if isinstance(magnetic_pressure, float) else None)
    if chains:
        images.append(chain_plot(plt, chains, flux, args.out))
    if brush:
        images.append(brush_height_plot(plt, brush, args.out))
    if flux:
        images.append(flux_plot(plt, flux, measured, args.out, args.case_name))
    snap = last_snapshot(args.dem_dir)
    snapshot_time = None
    if snap:
        name, snapshot_time = snapshot_plot(plt, h5py, np, snap,
                                            (args.sleeve_radius, args.drum_radius, (cx, cy), args.sleeve_sense), args.out)
        if name:
            images.append(name)
    images.append(series_plot(plt, series, nip_series, args.out, averaging_windows(args.dem_dir, os.path.join(args.out, "case_resolved.txt"))))

    run_times = []
    if run_times_table:
        run_times = list(zip(run_times_table["stage"], run_times_table["seconds"]))
    phases = read_phase_times(log)
    dem_done = read_log_line(log, "done:")
    run_summary = read_run_summary(os.path.join(args.dem_dir, "summary.csv"))
    development = development_plot(plt, args.dem_dir, run_summary, args.out)
    if development:
        images.append(development)
    profile_image = developed_profile_plot(plt, args.dem_dir, args.out)
    if profile_image:
        images.append(profile_image)
    flow = read_csv(os.path.join(args.dem_dir, "flow_report.csv"))
    rows = key_numbers(summary, nip_series, series, flux, run_summary, flow)
    build_index(args, images, rows, run_times, phases, snapshot_time, dem_done, run_summary)
    for a, b, c, d in rows:
        print(f"  {a:42s} {b}  {('[' + c + ']') if c else ''} {d}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
