#!/usr/bin/env python3
"""Two or more finished magbrush runs side by side: one HTML page (+ PNGs) to decide from.

Called by `magbrush compare RUN_A RUN_B [...]` (a run is a run folder: results/<case> or
results/<case>-<digest>, what `magbrush run` writes):

    compare.py --out DIR RUN_A RUN_B [RUN_C ...]

For every run it reads (what exists): dem/summary.csv (every measurement's key numbers with
standard errors), case_resolved.txt (or report/case_resolved.txt), variant.txt,
dem/nip_profile.csv, dem/toner_developed_profile.csv and the sleeve-flux profile of its stored
fields. It writes into DIR:

    index.html, index.md   the key numbers of each run as value ± standard error; for each run
                           after the first, its difference from the first and whether that is
                           beyond the combined error, |b - a| > 2 sqrt(se_a^2 + se_b^2); the
                           inputs that differ; the shift of each pole's sleeve-flux peak (angle
                           and Bn); the overlaid profiles
    compare.csv            the same numbers, one row per key and run (what the tests read)
    compare_*.png          the nip's slip, pressures and touching density, the sleeve flux and
                           the developed toner profile, each run one curve (needs matplotlib;
                           without it the page has the tables only)

The first run is the reference. Every file is written atomically (tmp + rename). Exit status:
0 written, 2 a run folder without dem/summary.csv.
"""
import argparse
import csv
import html
import math
import os
import sys

# Keys that are the run's place, not its physics: they differ between any two folders.
PLACE_KEYS = ("output.directory", "field.output_dir")


# ------------------------------------------------------------------------------------------
# Reading one run

def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


def read_columns(path):
    """Columns of a magbrush CSV by header name ('#' lines skipped); None when absent."""
    if not path or not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
    if len(rows) < 2:
        return None
    header, data = rows[0], rows[1:]
    return {name: [number(r[i]) if i < len(r) else float("nan") for r in data] for i, name in enumerate(header)}


def read_summary(path):
    """dem/summary.csv as an ordered list of (key, value, standard_error, unit, meaning)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(line for line in f if not line.startswith("#"))
        return [(r["key"], number(r.get("value")), number(r.get("standard_error")), r.get("unit", ""),
                 r.get("meaning", "")) for r in reader]


def read_resolved(run):
    """case_resolved.txt ("key = value" lines) as a dict, and the file's path ("" if none)."""
    for path in (os.path.join(run, "case_resolved.txt"), os.path.join(run, "report", "case_resolved.txt")):
        if os.path.exists(path):
            inputs = {}
            with open(path) as f:
                for line in f:
                    if line.startswith("#") or " = " not in line:
                        continue
                    key, value = line.split(" = ", 1)
                    inputs[key.strip()] = value.strip()
            return inputs, path
    return {}, ""


def read_variant(run):
    """The overrides variant.txt lists ("set key=value" lines)."""
    path = os.path.join(run, "variant.txt")
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [line[4:].strip() for line in f if line.startswith("set ")]


def flux_profile_path(run, inputs):
    """The sleeve-flux CSV of the run's stored fields. field.output_dir is relative to where the
    run was made: the folder that holds the run folder as output.directory names it."""
    name, fields, out = inputs.get("name"), inputs.get("field.output_dir", "").strip('"'), inputs.get(
        "output.directory", "").strip('"')
    if not name or not fields:
        return None
    bases = [os.getcwd()]
    run_abs = os.path.abspath(run).rstrip("/")
    if out and run_abs.endswith(os.path.normpath(out)):
        bases.insert(0, run_abs[: len(run_abs) - len(os.path.normpath(out))] or "/")
    for base in bases:
        path = os.path.join(base, fields, name + "_profile_sleeve.csv")
        if os.path.exists(path):
            return path
    return None


class Run:
    def __init__(self, folder):
        self.folder = folder
        self.name = os.path.basename(os.path.normpath(folder))
        self.summary = read_summary(os.path.join(folder, "dem", "summary.csv"))
        self.by_key = {k: (v, se, u, m) for k, v, se, u, m in self.summary}
        self.inputs, self.resolved_path = read_resolved(folder)
        self.overrides = read_variant(folder)
        self.nip = read_columns(os.path.join(folder, "dem", "nip_profile.csv"))
        nip_summary = read_columns(os.path.join(folder, "dem", "nip_summary.csv"))
        self.nip_samples = float("nan")
        if nip_summary and "key" in nip_summary:
            # read_columns made the key column numbers (nan): read the file's rows by position.
            with open(os.path.join(folder, "dem", "nip_summary.csv"), newline="") as f:
                for row in csv.reader(line for line in f if not line.startswith("#")):
                    if row and row[0] == "samples":
                        self.nip_samples = number(row[1])
        self.developed = read_columns(os.path.join(folder, "dem", "toner_developed_profile.csv"))
        flux = flux_profile_path(folder, self.inputs)
        self.flux = read_columns(flux) if flux else None

    def label(self, common=()):
        """The folder's name and the overrides that tell it from the other runs."""
        own = [o for o in self.overrides if o not in common]
        return self.name + (" (" + ", ".join(own) + ")" if own else "")


# ------------------------------------------------------------------------------------------
# The comparison

def fmt(v, digits=4):
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.{digits}g}"


def difference(a, b):
    """(b - a, combined standard error, verdict) of two (value, se) pairs. The verdict is
    'beyond' when |b - a| > 2 sqrt(se_a^2 + se_b^2), 'within' when not, 'no error' when either
    run gives no standard error (a number the run does not average: it cannot be judged)."""
    (va, sa), (vb, sb) = a, b
    d = vb - va
    if not (math.isfinite(sa) and math.isfinite(sb)):
        return d, float("nan"), "no error"
    combined = math.sqrt(sa * sa + sb * sb)
    if not math.isfinite(d):
        return d, combined, "no error"
    return d, combined, "beyond" if abs(d) > 2.0 * combined else "within"


def key_rows(runs):
    """One row per key (the keys in the first run's order, then any the others add): the key,
    its unit and meaning, and per run (value, se) or None."""
    keys = []
    for r in runs:
        keys += [k for k, *_ in r.summary if k not in keys]
    rows = []
    for k in keys:
        unit = meaning = ""
        cells = []
        for r in runs:
            if k in r.by_key:
                v, se, u, m = r.by_key[k]
                unit, meaning = unit or u, meaning or m
                cells.append((v, se))
            else:
                cells.append(None)
        rows.append((k, unit, meaning, cells))
    return rows


def differing_inputs(runs):
    """The resolved inputs whose values are not the same in every run (the place keys left out)."""
    keys = []
    for r in runs:
        keys += [k for k in r.inputs if k not in keys]
    out = []
    for k in keys:
        if k in PLACE_KEYS:
            continue
        values = [r.inputs.get(k, "(absent)") for r in runs]
        if len(set(values)) > 1:
            out.append((k, values))
    return out


def flux_peaks(flux, share=0.2):
    """The poles of a sleeve-flux profile: [(angle_deg, Bn_T)] at each local extremum of Bn
    whose size is at least `share` of the largest (the profile is periodic in angle)."""
    if not flux or "angle_deg" not in flux or "Bn_T" not in flux:
        return []
    a, b = flux["angle_deg"], flux["Bn_T"]
    n = len(b)
    top = max((abs(v) for v in b if math.isfinite(v)), default=0.0)
    peaks = []
    for i in range(n):
        prev, nxt = b[i - 1], b[(i + 1) % n]
        if abs(b[i]) >= share * top and (b[i] > 0 and b[i] >= prev and b[i] > nxt or
                                         b[i] < 0 and b[i] <= prev and b[i] < nxt):
            peaks.append((a[i], b[i]))
    return peaks


def peak_shifts(runs):
    """Each pole of the first run's sleeve flux and, per other run, the peak of the same sign
    nearest in angle: [(angle_a, Bn_a, [(d_angle, d_Bn) or None per other run])]."""
    reference = flux_peaks(runs[0].flux)
    rows = []
    for angle, value in reference:
        shifts = []
        for r in runs[1:]:
            same = [(x, v) for x, v in flux_peaks(r.flux) if (v > 0) == (value > 0)]
            if not same:
                shifts.append(None)
                continue
            x, v = min(same, key=lambda p: abs((p[0] - angle + 180.0) % 360.0 - 180.0))
            shifts.append(((x - angle + 180.0) % 360.0 - 180.0, v - value))
        rows.append((angle, value, shifts))
    return rows


def write_text(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def write_csv(path, runs, rows):
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["key", "unit", "run", "value", "standard_error", "difference_from_first",
                    "combined_standard_error", "verdict"])
        for k, unit, _, cells in rows:
            for i, (r, cell) in enumerate(zip(runs, cells)):
                if cell is None:
                    continue
                d = c = float("nan")
                verdict = "reference" if i == 0 else "absent in the first run"
                if i > 0 and cells[0] is not None:
                    d, c, verdict = difference(cells[0], cell)
                w.writerow([k, unit, r.folder, repr(cell[0]), repr(cell[1]), repr(d), repr(c), verdict])
    os.replace(tmp, path)


# ------------------------------------------------------------------------------------------
# Plots (optional: matplotlib)

def plots(runs, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return [], "matplotlib is not installed (Debian: python3-matplotlib): the page has the tables only"
    images = []
    common = set.intersection(*(set(r.overrides) for r in runs)) if runs else set()
    label = {id(r): r.label(common) for r in runs}

    def overlay(name, title, xlabel, ylabel, curves, hline=None, hlabel=None):
        if not curves:
            return
        fig, ax = plt.subplots(figsize=(7.5, 4))
        for label, x, y, style in curves:
            ax.plot(x, y, style, label=label, ms=3)
        if hline is not None:
            ax.axhline(hline, color="0.4", ls="--", lw=1, label=hlabel)
        ax.set_title(title)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        # Below the axes: the labels carry each run's overrides and would hide the curves.
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16))
        tmp = os.path.join(out, name + ".tmp")
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
        os.replace(tmp, os.path.join(out, name))
        plt.close(fig)
        images.append(name)

    def masked(run, column, scale=1.0):
        """A nip profile column with its sparse bins blanked, as the report leaves them out
        (tools/report.py sparse_bins): fewer contact samples than a tenth of the window's
        samples. A bin averaged over one contact is noise, and it would set the plot's scale."""
        prof = run.nip
        counts = prof.get("contact_samples")
        n = run.nip_samples
        threshold = max(2.0, 0.1 * n) if math.isfinite(n) and n > 0 else 2.0
        return [v * scale if (counts is None or not (0 < counts[i] < threshold)) else float("nan")
                for i, v in enumerate(prof[column])]

    nip_x = "x along the nip from the gap centre [mm] (positive downstream)"
    with_nip = [r for r in runs if r.nip and "x_mm" in r.nip]
    overlay("compare_nip_slip.png", "Slip of the beads touching the drum (contact points)", nip_x, "slip [m/s]",
            [(label[id(r)], r.nip["x_mm"], masked(r, "slip_speed_m_s"), "o-") for r in with_nip
             if "slip_speed_m_s" in r.nip])
    overlay("compare_nip_pressure.png", "Normal pressure on the drum", nip_x, "normal pressure [kPa]",
            [(label[id(r)], r.nip["x_mm"], masked(r, "normal_pressure_Pa", 1e-3), "o-") for r in with_nip
             if "normal_pressure_Pa" in r.nip])
    overlay("compare_nip_density.png", "Beads touching the drum", nip_x, "touching beads [1/mm²]",
            [(label[id(r)], r.nip["x_mm"], masked(r, "density_per_mm2"), "o-") for r in with_nip
             if "density_per_mm2" in r.nip])
    overlay("compare_flux.png", "Normal flux density on the sleeve", "angle [deg]", "Bn [mT]",
            [(label[id(r)], r.flux["angle_deg"], [v * 1e3 for v in r.flux["Bn_T"]], "-") for r in runs
             if r.flux and "angle_deg" in r.flux and "Bn_T" in r.flux])
    overlay("compare_developed_profile.png", "Developed toner across one image period",
            "position from the exposed strip's centre [mm]", "toner mass per area [kg/m²]",
            [(label[id(r)], r.developed["position_mm"], r.developed["toner_mass_per_area_kg_per_m2"], "o-")
             for r in runs if r.developed and "position_mm" in r.developed
             and "toner_mass_per_area_kg_per_m2" in r.developed])
    return images, ""


# ------------------------------------------------------------------------------------------
# The page

def value_text(cell):
    if cell is None:
        return "—"
    v, se = cell
    return fmt(v) + (" ± " + fmt(se, 2) if math.isfinite(se) else "")


def build_page(runs, rows, inputs, images, note, out):
    e = html.escape
    title = "magbrush compare: " + " vs ".join(r.name for r in runs)
    verdict_text = {"beyond": "beyond the combined error", "within": "within the combined error",
                    "no error": "no standard error to judge by"}
    h = ["<!DOCTYPE html>", "<html><head><meta charset='utf-8'>", f"<title>{e(title)}</title>",
         "<style>body{font-family:sans-serif;max-width:1200px;margin:2em auto;} table{border-collapse:collapse;}"
         " td,th{border:1px solid #bbb;padding:3px 8px;vertical-align:top;} td.beyond{background:#fde2c8;}"
         " img{max-width:100%;margin:6px 0;} .meaning{color:#666;font-size:85%;}</style></head><body>",
         f"<h1>{e(title)}</h1>", "<h2>Runs</h2><table><tr><th></th><th>folder</th><th>overrides</th><th>inputs</th></tr>"]
    md = [f"# {title}", "", "## Runs", "", "| | folder | overrides |", "|---|---|---|"]
    for i, r in enumerate(runs):
        role = "reference" if i == 0 else f"run {chr(ord('A') + i)}"
        link = (f"<a href='{e(os.path.relpath(r.resolved_path, out))}'>case_resolved.txt</a>" if r.resolved_path
                else "—")
        h.append(f"<tr><td>{chr(ord('A') + i)} ({e(role)})</td><td>{e(r.folder)}</td>"
                 f"<td>{e(', '.join(r.overrides) or 'none: the case as its file gives it')}</td><td>{link}</td></tr>")
        md.append(f"| {chr(ord('A') + i)} | {r.folder} | {', '.join(r.overrides) or 'none'} |")
    h.append("</table>")
    md.append("")

    h += ["<h2>Key numbers</h2>",
          "<p>Value ± standard error (block averages over each run's window). A difference is marked "
          "<b>beyond</b> the combined error when |b − a| &gt; 2 √(se<sub>a</sub>² + se<sub>b</sub>²); a number "
          "without a standard error cannot be judged that way.</p>", "<table><tr><th>quantity</th><th>unit</th>"]
    h += [f"<th>{chr(ord('A') + i)}</th>" for i in range(len(runs))]
    h += [f"<th>{chr(ord('A') + i)} − A</th>" for i in range(1, len(runs))]
    h.append("</tr>")
    md += ["## Key numbers", "", "| quantity | unit | " + " | ".join(chr(ord('A') + i) for i in range(len(runs))) +
           " | " + " | ".join(f"{chr(ord('A') + i)} − A" for i in range(1, len(runs))) + " |",
           "|---" * (2 + 2 * len(runs) - 1) + "|"]
    for k, unit, meaning, cells in rows:
        tds = [f"<td>{e(value_text(c))}</td>" for c in cells]
        diffs, md_diffs = [], []
        for c in cells[1:]:
            if c is None or cells[0] is None:
                diffs.append("<td>—</td>")
                md_diffs.append("—")
                continue
            d, comb, verdict = difference(cells[0], c)
            text = fmt(d) + (" ± " + fmt(comb, 2) if math.isfinite(comb) else "") + ": " + verdict_text[verdict]
            diffs.append(f"<td class='{verdict.replace(' ', '_')}'>{e(text)}</td>")
            md_diffs.append(("**" + text + "**") if verdict == "beyond" else text)
        h.append(f"<tr><td>{e(k)}<div class='meaning'>{e(meaning)}</div></td><td>{e(unit)}</td>" + "".join(tds) +
                 "".join(diffs) + "</tr>")
        md.append(f"| {k} | {unit} | " + " | ".join(value_text(c) for c in cells) + " | " + " | ".join(md_diffs) + " |")
    h.append("</table>")
    md.append("")

    h.append("<h2>Inputs that differ</h2>")
    md += ["## Inputs that differ", ""]
    if inputs:
        h.append("<table><tr><th>key</th>" + "".join(f"<th>{chr(ord('A') + i)}</th>" for i in range(len(runs))) +
                 "</tr>")
        h += ["<tr><td>" + e(k) + "</td>" + "".join(f"<td>{e(v)}</td>" for v in vals) + "</tr>" for k, vals in inputs]
        h.append("</table>")
        md += ["| key | " + " | ".join(chr(ord('A') + i) for i in range(len(runs))) + " |",
               "|---" * (1 + len(runs)) + "|"]
        md += [f"| {k} | " + " | ".join(vals) + " |" for k, vals in inputs]
    else:
        none = ("none (the runs have the same resolved inputs)" if all(r.inputs for r in runs)
                else "unknown: a run folder has no case_resolved.txt")
        h.append(f"<p>{e(none)}</p>")
        md.append(none)
    md.append("")

    shifts = peak_shifts(runs) if runs[0].flux else []
    if shifts and any(r.flux for r in runs[1:]):
        h += ["<h2>Sleeve flux: the poles' peaks</h2>",
              "<table><tr><th>pole peak in A</th>" +
              "".join(f"<th>{chr(ord('A') + i)} − A</th>" for i in range(1, len(runs))) + "</tr>"]
        md += ["## Sleeve flux: the poles' peaks", "",
               "| pole peak in A | " + " | ".join(f"{chr(ord('A') + i)} − A" for i in range(1, len(runs))) + " |",
               "|---" * len(runs) + "|"]
        for angle, value, others in shifts:
            cells = ["—" if o is None else f"{o[0]:+.2f} deg, {o[1] * 1e3:+.2f} mT" for o in others]
            first = f"{angle:.2f} deg, {value * 1e3:.2f} mT"
            h.append(f"<tr><td>{e(first)}</td>" + "".join(f"<td>{e(c)}</td>" for c in cells) + "</tr>")
            md.append(f"| {first} | " + " | ".join(cells) + " |")
        h.append("</table>")
        md.append("")

    h.append("<h2>Profiles</h2>")
    md += ["## Profiles", ""]
    if note:
        h.append(f"<p>{e(note)}</p>")
        md.append(note)
    if images:
        h.append("<p>The nip profiles leave out the bins averaged over fewer contacts than a tenth of the window's "
                 "samples, as the report does.</p>")
    h += [f"<p><a href='{e(img)}'><img src='{e(img)}' alt='{e(img)}'></a></p>" for img in images]
    md += [f"![{img}]({img})" for img in images]
    h.append("</body></html>")
    write_text(os.path.join(out, "index.html"), "\n".join(h) + "\n")
    write_text(os.path.join(out, "index.md"), "\n".join(md) + "\n")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="folder for index.html, compare.csv and the PNGs")
    p.add_argument("runs", nargs="+", help="run folders (results/<case>[-<digest>]); the first is the reference")
    args = p.parse_args(argv)
    if len(args.runs) < 2:
        print("compare.py: give at least two run folders", file=sys.stderr)
        return 2
    for run in args.runs:
        if not os.path.exists(os.path.join(run, "dem", "summary.csv")):
            print(f"compare.py: {run}: no dem/summary.csv (not a finished run folder)", file=sys.stderr)
            return 2
    runs = [Run(r) for r in args.runs]
    os.makedirs(args.out, exist_ok=True)
    rows = key_rows(runs)
    write_csv(os.path.join(args.out, "compare.csv"), runs, rows)
    images, note = plots(runs, args.out)
    build_page(runs, rows, differing_inputs(runs), images, note, args.out)
    beyond = sum(1 for _, _, _, cells in rows for c in cells[1:]
                 if c is not None and cells[0] is not None and difference(cells[0], c)[2] == "beyond")
    print(f"compare.py: {len(rows)} key numbers of {len(runs)} runs, {beyond} differences beyond the combined error")
    return 0


if __name__ == "__main__":
    sys.exit(main())
