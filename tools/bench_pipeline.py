#!/usr/bin/env python3
"""The pipeline's error-against-cost table: every accuracy knob of the
field solver, the DEM's magnetics and the electrostatics, varied ONE AT A TIME from a
converged reference, against the observables a user reads, with the wall time of the stage
the knob affects.

    tools/bench --pipeline [--quick] [--out DIR] [--threads N] [--repeats N] [--reuse]

Scenes and observables (docs/pipeline_cost.md):
  field of kawamoto_nip, field of kweon_development   sleeve |B| profile (the field stage's
      results/fields/<name>_profile_sleeve.csv): knobs element degree, mesh size
  nip: kawamoto_nip at a small size (a 0.25 mm slab, 1,075 beads, 0.5 ms)   slip, pressure,
      touching-bead density (dem/summary.csv, dem/nip_profile.csv): knobs time-step fraction,
      magnetic far-field order, magnetic refresh, staleness, field grid spacing
  development cell (tests/scenes/development, Kweon's scene reduced to 60 us)   TMA on the
      image and the background (fog) (dem/summary.csv): knobs Coulomb far-field order,
      electric hold distance, toner stiffness factor (the toner time-step method), time-step
      fraction
The DMA (developer mass per area on the sleeve) has no measurement in magbrush yet: it is
listed as "not measured".

Every DEM scene also runs the reference again with other seeds (dem.seed = 2, 3; --repeats,
--quick: one): the largest relative change is the run-to-run noise; an error not above it is
reported as "below noise".

Outputs in --out (default build/bench_pipeline): pipeline_cost.csv (one row per scene, knob,
setting, observable), pipeline_cost.png (relative error against wall time, log-log, one
curve per knob, one panel per scene and observable), pipeline_cost.md (the printed tables).
Each setting runs in its own folder under --out; --reuse takes a finished setting's stored
result (result.json) instead of running it again.
"""

import argparse
import csv
import datetime
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pipeline_cost_table as table  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Knob:
    """One accuracy knob: its settings as (label, overrides), the reference's label, the stage
    whose wall time is its cost, and the labels run by --quick."""

    def __init__(self, name, meaning, stage, reference, settings, quick):
        self.name, self.meaning, self.stage = name, meaning, stage
        self.reference, self.settings, self.quick = reference, settings, quick


def mesh_scale(factor):
    """The three element sizes of the field meshes scaled together from their defaults."""
    return {"field.mesh_size_far": "%gmm" % (2.0 * factor),
            "field.mesh_size_sleeve": "%gmm" % (0.25 * factor),
            "field.mesh_size_gap": "%gum" % (20.0 * factor)}


def grid_scale(factor):
    """The polar magnetic grid's spacings scaled together from their defaults."""
    return {"field.grid_radial_spacing": "%gum" % (50.0 * factor),
            "field.grid_angular_spacing": "%gdeg" % (0.25 * factor)}


# ---------------------------------------------------------------------------------------------
# The studies. A reference is the most accurate setting of every knob that the 20-25 minute
# budget of the whole table affords; each knob's settings relax one knob from it.

# Degree 4 on the default mesh: a finer mesh than the default makes Gmsh's nip mesh (10 um in
# the gap) cost minutes. The field solver checks the reference against the exact multipole
# ring (its error is printed with the table).
FIELD_REFERENCE = dict(mesh_scale(1.0), **{"field.element_degree": "4"})
FIELD_KNOBS = [
    Knob("element degree", "field.element_degree (FE_Q degree of both field problems)", "field",
         "4", [("1", {"field.element_degree": "1"}), ("2", {"field.element_degree": "2"}),
               ("3 (default)", {"field.element_degree": "3"})], quick=["2"]),
    Knob("mesh size", "field.mesh_size_far/_sleeve/_gap scaled together (x1 = 2 mm, 0.25 mm, 20 um)",
         "mesh+field", "x1 (default)", [("x4", mesh_scale(4.0)), ("x2", mesh_scale(2.0))],
         quick=["x2"]),
]

# The placed quick scene of kawamoto_nip.yaml reduced to a quarter of its slab (0.25 mm, 1,075 beads
# at the same solid fraction in the same box), 0.1 ms of settling and 0.4 ms of turning,
# averaged over the last 0.3 ms.
NIP_SCENE = {
    "populations.carrier.count": "1075",
    "populations.carrier.insert_box": "[[12.1mm,-2.5mm,0mm],[13.0mm,1.5mm,0.25mm]]",
    "dem.periodic_length": "0.25mm", "dem.settle_time": "0.1ms", "dem.duration": "0.5ms",
    "nip.average_from": "0.2ms", "dem.output_interval": "0.5ms", "output.xdmf": "false",
    "dem.time_step": "0s",
}
NIP_REFERENCE = dict(grid_scale(0.5), **{
    "dem.time_step_safety": "0.2", "dem.magnetic_far_order": "4", "dem.magnetic_refresh": "1us",
    "dem.magnetic_staleness": "0.01"})
NIP_KNOBS = [
    Knob("time-step fraction", "dem.time_step_safety: the step as a fraction of the stable limit (54 ns here)",
         "dem", "0.2 (default)", [("0.8", {"dem.time_step_safety": "0.8"}),
                                  ("0.4", {"dem.time_step_safety": "0.4"})], quick=["0.8"]),
    Knob("magnetic far-field order", "dem.magnetic_far_order: Taylor order of the cell multipoles",
         "dem", "4", [("0", {"dem.magnetic_far_order": "0"}), ("1", {"dem.magnetic_far_order": "1"}),
                      ("2 (default)", {"dem.magnetic_far_order": "2"})], quick=["0"]),
    Knob("magnetic refresh", "dem.magnetic_refresh: interval of the full magnetic evaluation",
         "dem", "1us", [("20us", {"dem.magnetic_refresh": "20us"}),
                        ("5us (case)", {"dem.magnetic_refresh": "5us"})], quick=["20us"]),
    Knob("magnetic staleness", "dem.magnetic_staleness: move (x radius) that refreshes held forces early",
         "dem", "0.01", [("0.2", {"dem.magnetic_staleness": "0.2"}),
                         ("0.05 (default)", {"dem.magnetic_staleness": "0.05"})], quick=[]),
    Knob("field grid spacing", "field.grid_radial/_angular_spacing scaled together (x1 = 50 um, 0.25 deg)",
         "field", "x0.5", [("x2", grid_scale(2.0)), ("x1 (default)", grid_scale(1.0))], quick=[]),
]

# The development cell shortened from 60 us to 40 us, the TMA averaged over 20-40 us.
DEVELOPMENT_SCENE = {"dem.duration": "40us", "dem.output_interval": "40us",
                     "development.average_from": "20us", "output.xdmf": "false"}
DEVELOPMENT_REFERENCE = {"electric.coulomb_order": "6", "electric.hold_distance": "5nm",
                         "dem.toner_stiffness_factor": "1", "dem.time_step_safety": "0.2"}
DEVELOPMENT_KNOBS = [
    Knob("Coulomb far-field order", "electric.coulomb_order: Taylor order of the Coulomb cell multipoles",
         "dem", "6", [("2", {"electric.coulomb_order": "2"}),
                      ("4 (default)", {"electric.coulomb_order": "4"})], quick=["2"]),
    Knob("electric hold distance", "electric.hold_distance: move that re-evaluates the held electric forces",
         "dem", "5nm", [("100nm", {"electric.hold_distance": "100nm"}),
                        ("20nm (default)", {"electric.hold_distance": "20nm"})], quick=["100nm"]),
    Knob("toner stiffness factor", "dem.toner_stiffness_factor: softer toner contacts for a larger step "
         "(the toner time-step method)", "dem", "1 (default)",
         [("0.3", {"dem.toner_stiffness_factor": "0.3"})], quick=[]),
    Knob("time-step fraction", "dem.time_step_safety: the step as a fraction of the stable limit (2.5 ns here)",
         "dem", "0.2 (default)", [("0.5", {"dem.time_step_safety": "0.5"})], quick=[]),
]


# Lines printed under the table (the references' own checks).
NOTES = []

# ---------------------------------------------------------------------------------------------
# Running magbrush.

def magbrush(args, cwd, log):
    """Runs build/bin/magbrush with the arguments in cwd, its output appended to log; returns
    the wall time in seconds. A failure stops the benchmark with the log's tail."""
    exe = os.path.join(os.environ.get("BUILD_DIR", os.path.join(ROOT, "build")), "bin", "magbrush")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start = time.monotonic()
    with open(log, "a") as f:
        f.write("$ magbrush %s\n" % " ".join(args))
        f.flush()
        rc = subprocess.call([exe] + args, cwd=cwd, stdout=f, stderr=subprocess.STDOUT, env=env)
    seconds = time.monotonic() - start
    if rc != 0:
        with open(log) as f:
            tail = f.read()[-3000:]
        raise RuntimeError("magbrush %s failed (exit %d) in %s:\n%s" % (args[0], rc, cwd, tail))
    return seconds


def set_args(overrides):
    # Every setting runs in a folder of its own: its results go to that folder's results/, not
    # to the run folder named by the overrides' digest, so that a DEM setting finds the fields
    # its field folder solved whatever the overrides of either.
    out = ["--set", "output.directory=results"]
    for k, v in overrides.items():
        out += ["--set", "%s=%s" % (k, v)]
    return out


# Wall time of every magbrush call of the settings in this table, run now or reused (the
# table's own cost, without the shared untimed field preparation).
RUN_SECONDS = []


def stored(folder, reuse):
    path = os.path.join(folder, "result.json")
    if reuse and os.path.exists(path):
        with open(path) as f:
            done = json.load(f)
        RUN_SECONDS.append(run_seconds(done))
        return done
    if os.path.exists(folder):
        shutil.rmtree(folder)
    os.makedirs(folder)
    return None


def run_seconds(result):
    return sum(v for k, v in result["times"].items() if k != "mesh+field")


def store(folder, result):
    RUN_SECONDS.append(run_seconds(result))
    with open(os.path.join(folder, "result.json"), "w") as f:
        json.dump(result, f, indent=1)
    return result


def read_sleeve_profile(path):
    """|B| on the sleeve against angle, from the field stage's profile CSV."""
    with open(path) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return [math.hypot(float(r["Bn_T"]), float(r["Bt_T"])) for r in rows]


def run_field(case, name, overrides, folder, reuse):
    """Mesh and magnetic field of a case in its own folder; the sleeve |B| profile and the
    wall times of the mesh and field stages."""
    done = stored(folder, reuse)
    if done:
        return done
    log = os.path.join(folder, "log.txt")
    args = set_args(overrides)
    mesh_s = magbrush(["mesh", case] + args, folder, log)
    field_s = magbrush(["field", case, "--only", "magnetic", "--no-vtu"] + args, folder, log)
    profile = read_sleeve_profile(os.path.join(folder, "results", "fields", name + "_profile_sleeve.csv"))
    with open(log) as f:
        check = re.search(r"vs the exact multipole ring: ([-+0-9.eE]+)", f.read())
    return store(folder, {"times": {"mesh": mesh_s, "field": field_s, "mesh+field": mesh_s + field_s},
                          "profile": profile, "exact_ring_error": float(check.group(1)) if check else None})


def read_summary(folder):
    """dem/summary.csv: {key: value} of every measurement's key numbers."""
    with open(os.path.join(folder, "summary.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return {r["key"]: float(r["value"]) for r in rows}


def mean_nip_slip(folder):
    """The slip of the touching beads averaged over the whole nip profile, each bin weighted by
    its contact samples (less noisy than the centre bin alone)."""
    with open(os.path.join(folder, "nip_profile.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    weight = sum(float(r["contact_samples"]) for r in rows if r["slip_speed_m_s"] != "nan")
    total = sum(float(r["contact_samples"]) * float(r["slip_speed_m_s"])
                for r in rows if r["slip_speed_m_s"] != "nan")
    return total / weight if weight > 0 else math.nan


# The DEM observables: (name in the table, how it is read from the dem folder).
NIP_OBSERVABLES = [
    ("slip at gap centre [m/s]", lambda d, s: s["slip_at_gap_centre_m_s"]),
    ("mean slip over nip [m/s]", lambda d, s: mean_nip_slip(d)),
    ("peak normal pressure [Pa]", lambda d, s: s["peak_normal_pressure_Pa"]),
    ("normal force per length [N/m]", lambda d, s: s["normal_force_per_length_N_m"]),
    ("density at gap centre [1/mm^2]", lambda d, s: s["density_at_gap_centre_per_mm2"]),
    ("touching beads", lambda d, s: s["touching_beads"]),
]
DEVELOPMENT_OBSERVABLES = [
    ("TMA on the image [kg/m^2]", lambda d, s: s["tma_kg_per_m2"]),
]


def run_dem(case, overrides, field_folder, folder, observables, threads, reuse, own_field=False):
    """The DEM of a case on the fields in field_folder (its working folder; with own_field the
    setting's folder gets its own copy of the meshes and solves its own field, timed), outputs
    in folder/dem; returns the observables and the wall times of the field and dem stages."""
    done = stored(folder, reuse)
    if done:
        return done
    log = os.path.join(folder, "log.txt")
    args = set_args(overrides)
    times = {}
    cwd = field_folder
    if own_field:
        shutil.copytree(os.path.join(field_folder, "meshes"), os.path.join(folder, "meshes"))
        times["field"] = magbrush(["field", case, "--no-vtu"] + args, folder, log)
        cwd = folder
    dem_dir = os.path.join(folder, "dem")
    times["dem"] = magbrush(["dem", case, "--threads", str(threads), "--output", dem_dir] + args, cwd, log)
    summary = read_summary(dem_dir)
    values = {name: read(dem_dir, summary) for name, read in observables}
    return store(folder, {"times": times, "values": values})


def time_field(case, overrides, field_folder, folder, reuse):
    """The wall time of the field stage of a setting, solved in its own folder."""
    done = stored(folder, reuse)
    if done:
        return done["times"]["field"]
    shutil.copytree(os.path.join(field_folder, "meshes"), os.path.join(folder, "meshes"))
    seconds = magbrush(["field", case, "--no-vtu"] + set_args(overrides), folder, os.path.join(folder, "log.txt"))
    return store(folder, {"times": {"field": seconds}})["times"]["field"]


def prepare_fields(case, overrides, folder, reuse):
    """The meshes and fields a DEM study's settings share, solved once (untimed)."""
    marker = os.path.join(folder, "fields_ready")
    if reuse and os.path.exists(marker):
        return
    if os.path.exists(folder):
        shutil.rmtree(folder)
    os.makedirs(folder)
    log = os.path.join(folder, "log.txt")
    magbrush(["mesh", case] + set_args(overrides), folder, log)
    magbrush(["field", case, "--no-vtu"] + set_args(overrides), folder, log)
    open(marker, "w").close()


# ---------------------------------------------------------------------------------------------
# The table rows.

def rows_of(scene, knob, setting, is_reference, stage, seconds, values, references, noises):
    out = []
    for obs, value in values.items():
        ref = references[obs]
        if isinstance(value, list):  # a profile: its peak is the value, the error the profile's
            err = table.profile_relative_error(value, ref)
            value, ref = max(value), max(ref)
        else:
            err = table.relative_error(value, ref)
        noise = noises.get(obs, 0.0)
        out.append({"scene": scene, "knob": knob, "setting": setting,
                    "is_reference": "1" if is_reference else "0", "stage": stage,
                    "wall_time_s": "%.4g" % seconds, "observable": obs, "value": "%.6g" % value,
                    "reference": "%.6g" % ref, "relative_error": "%.4g" % err,
                    "noise": "%.4g" % noise, "verdict": table.verdict(err, noise)})
    return out


def chosen(knob, quick):
    return [(label, o) for label, o in knob.settings if not quick or label in knob.quick]


def field_study(scene, case, name, out, quick, reuse, log):
    ref = run_field(case, name, FIELD_REFERENCE, os.path.join(out, slug(scene), "reference"), reuse)
    NOTES.append("%s: the reference (degree 4, default mesh) against the field solver's exact multipole "
                 "ring: max |dB| / peak = %s on the sleeve." % (scene, ref["exact_ring_error"]))
    refs = {"sleeve B profile [T]": ref["profile"]}
    rows = []
    for knob in FIELD_KNOBS:
        if not chosen(knob, quick):
            continue
        rows += rows_of(scene, knob.name, knob.reference, True, knob.stage, ref["times"][knob.stage],
                        refs, refs, {})
        for label, o in chosen(knob, quick):
            folder = os.path.join(out, slug(scene), slug(knob.name, label))
            r = run_field(case, name, dict(FIELD_REFERENCE, **o), folder, reuse)
            log("  %s: %s = %s: %.1f s" % (scene, knob.name, label, r["times"][knob.stage]))
            rows += rows_of(scene, knob.name, label, False, knob.stage, r["times"][knob.stage],
                            {"sleeve B profile [T]": r["profile"]}, refs, {})
    return rows


def dem_study(scene, case, base, reference, knobs, observables, out, quick, threads, reuse, log,
              repeat_count):
    field_folder = os.path.join(out, slug(scene), "fields")
    prepare_fields(case, dict(base, **reference), field_folder, reuse)
    settings = dict(base, **reference)
    ref = run_dem(case, settings, field_folder, os.path.join(out, slug(scene), "reference"), observables,
                  threads, reuse)
    log("  %s: reference: %.1f s" % (scene, ref["times"]["dem"]))
    # The reference again with other seeds (2, 3, ...): the noise of an observable is the
    # largest relative change among the repeats (one repeat is a single sample of the spread).
    repeats = []
    for seed in range(2, 2 + repeat_count):
        folder = os.path.join(out, slug(scene), "seed_repeat" if seed == 2 else "seed_repeat_%d" % seed)
        repeats.append((seed, run_dem(case, dict(settings, **{"dem.seed": str(seed)}), field_folder, folder,
                                      observables, threads, reuse)))
        log("  %s: seed repeat (dem.seed=%d): %.1f s" % (scene, seed, repeats[-1][1]["times"]["dem"]))
    refs = ref["values"]
    noises = {obs: max(table.relative_error(r["values"][obs], refs[obs]) for _, r in repeats) for obs in refs}
    rows = []
    for seed, r in repeats:
        rows += rows_of(scene, table.SEED_REPEAT, "dem.seed=%d" % seed, False, "dem", r["times"]["dem"],
                        r["values"], refs, noises)
    for knob in knobs:
        if not chosen(knob, quick):
            continue
        own_field = knob.stage == "field"
        ref_seconds = ref["times"]["dem"]
        if own_field:  # the reference's field, timed the same way as the settings' fields (its
            # DEM would repeat the reference bit for bit: the same field, the same seed)
            ref_seconds = time_field(case, settings, field_folder,
                                     os.path.join(out, slug(scene), slug(knob.name, "reference")), reuse)
        rows += rows_of(scene, knob.name, knob.reference, True, knob.stage, ref_seconds, refs, refs, noises)
        for label, o in chosen(knob, quick):
            folder = os.path.join(out, slug(scene), slug(knob.name, label))
            r = run_dem(case, dict(settings, **o), field_folder, folder, observables, threads, reuse,
                        own_field=own_field)
            log("  %s: %s = %s: %.1f s" % (scene, knob.name, label, r["times"][knob.stage]))
            rows += rows_of(scene, knob.name, label, False, knob.stage, r["times"][knob.stage],
                            r["values"], refs, noises)
    return rows


def slug(*words):
    """A folder name from the words: letters and digits, the rest underscores."""
    return "".join(c if c.isalnum() else "_" for c in "_".join(words)).strip("_")


def not_measured_rows(scene, observable):
    return [{"scene": scene, "knob": "-", "setting": "-", "is_reference": "0", "stage": "-",
             "wall_time_s": "nan", "observable": observable, "value": "nan", "reference": "nan",
             "relative_error": "nan", "noise": "nan", "verdict": "not measured"}]


# ---------------------------------------------------------------------------------------------
# Output: the printed tables and the figure.

def markdown(rows, header):
    lines = [header, "", "Each knob relaxed from the reference (cost / reference: the wall time of the stage "
             "the knob affects, divided by the reference's):", "", "| scene | knob | setting | stage | wall time [s] | cost / reference | observable "
             "| value | reference | relative error |", "|---|---|---|---|---|---|---|---|---|---|"]
    ref_time = {}
    for r in rows:
        if r["is_reference"] == "1":
            ref_time[(r["scene"], r["knob"])] = float(r["wall_time_s"])
    seed_ref = {(r["scene"]): float(r["wall_time_s"]) for r in rows
                if r["is_reference"] == "1" and r["stage"] == "dem"}
    for r in rows:
        if r["is_reference"] == "1":
            continue  # the reference's rows (error 0) are in the CSV; the ratio column uses them
        if r["verdict"] == "not measured":
            lines.append("| %s | - | - | - | - | - | %s | not measured yet | - | - |" % (r["scene"], r["observable"]))
            continue
        base = ref_time.get((r["scene"], r["knob"])) or seed_ref.get(r["scene"])
        ratio = float(r["wall_time_s"]) / base if base else math.nan
        if r["knob"] == table.SEED_REPEAT:
            error = "%s (seed repeat)" % r["relative_error"]
        elif r["verdict"] == table.BELOW_NOISE:
            error = "below noise (%s <= %.2g)" % (r["relative_error"], float(r["noise"]))
        else:
            error = r["verdict"]
        lines.append("| %s | %s | %s | %s | %s | %.2f | %s | %s | %s | %s |" % (
            r["scene"], r["knob"], r["setting"], r["stage"], r["wall_time_s"], ratio, r["observable"],
            r["value"], r["reference"], error))
    lines += ["", "Cheapest setting of each knob within 1 % and 0.1 % of the reference (an error below "
              "the noise certifies only the noise):", "",
              "| scene | observable | noise (seed repeats) | knob | within 1 % | within 0.1 % |",
              "|---|---|---|---|---|---|"]
    # An observable whose noise exceeds both tolerances for every knob gets one line.
    for (scene, observable), entries in table.group(table.selection_table(rows), "scene", "observable").items():
        if all(e[tol].startswith("noise") for e in entries for tol in (1e-2, 1e-3)):
            lines.append("| %s | %s | %.2g | all: %s | noise above tolerance | noise above tolerance |" % (
                scene, observable, max(e["noise"] for e in entries), ", ".join(e["knob"] for e in entries)))
            continue
        for e in entries:
            lines.append("| %s | %s | %.2g | %s | %s | %s |" % (e["scene"], e["observable"], e["noise"], e["knob"],
                                                              e[1e-2], e[1e-3]))
    for r in rows:
        if r["verdict"] == "not measured":
            lines.append("| %s | %s | - | - | not measured yet | not measured yet |" % (r["scene"], r["observable"]))
    return "\n".join(lines) + "\n"


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    measured = [r for r in rows if r["verdict"] != "not measured" and r["is_reference"] == "0"
                and r["knob"] != table.SEED_REPEAT]
    panels = table.group(measured, "scene", "observable")
    ncol = 3
    nrow = (len(panels) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 3.9 * nrow), squeeze=False)
    floor = 1e-7
    for ax, ((scene, obs), prow) in zip(axes.flat, panels.items()):
        noise = max(float(r["noise"]) for r in prow)
        for (knob,), krows in table.group(prow, "knob").items():
            krows = sorted(krows, key=lambda r: float(r["wall_time_s"]))
            t = [float(r["wall_time_s"]) for r in krows]
            e = [max(float(r["relative_error"]), floor) for r in krows]
            line, = ax.plot(t, e, "-", label=knob)
            for ti, ei, r in zip(t, e, krows):
                hollow = r["verdict"] == table.BELOW_NOISE
                ax.plot([ti], [ei], "o", color=line.get_color(), mfc="none" if hollow else line.get_color())
                ax.annotate(r["setting"].split(" ")[0], (ti, ei), fontsize=7, xytext=(3, 3),
                            textcoords="offset points")
        for tol, style in ((1e-2, ":"), (1e-3, "-.")):
            ax.axhline(tol, color="grey", ls=style, lw=0.8)
        if noise > 0:
            ax.axhline(noise, color="red", ls="--", lw=0.8, label="noise (seed repeats)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        times = [float(r["wall_time_s"]) for r in prow]
        if max(times) > 10 * min(times):  # else the minor ticks carry the only labels
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        else:
            ax.xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%.3g"))
        ax.set_title("%s: %s" % (scene, obs), fontsize=9)
        ax.set_xlabel("wall time of the stage [s]")
        ax.set_ylabel("relative error vs reference")
        ax.legend(fontsize=7)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    fig.suptitle("magbrush pipeline: error against cost (benchmark output; hollow = below noise; "
                 "dotted 1 %, dash-dot 0.1 %)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="a subset of the settings (one field scene, 3 nip and 2 development knobs, one seed repeat)")
    p.add_argument("--out", default=os.path.join(ROOT, "build", "bench_pipeline"),
                   help="where the settings run and the tables go (default build/bench_pipeline)")
    p.add_argument("--threads", type=int, default=1, help="OpenMP threads of each DEM run (default 1)")
    p.add_argument("--reuse", action="store_true", help="reuse the stored results of finished settings")
    p.add_argument("--repeats", type=int, default=0,
                   help="seed repeats of each DEM reference for the noise (default: 2, --quick: 1)")
    a = p.parse_args()
    repeats = a.repeats or (1 if a.quick else 2)
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    start = time.monotonic()
    started = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    load = os.getloadavg()

    def log(msg):
        print("[%6.0f s] %s" % (time.monotonic() - start, msg), flush=True)

    nip_case = os.path.join(ROOT, "cases", "kawamoto_nip.yaml")
    kweon_case = os.path.join(ROOT, "cases", "kweon_development.yaml")
    cell_case = os.path.join(ROOT, "tests", "scenes", "development", "development_cell.yaml")
    rows = []
    log("field stage: kawamoto_nip")
    rows += field_study("field kawamoto_nip", nip_case, "kawamoto_nip", out, a.quick, a.reuse, log)
    if not a.quick:
        log("field stage: kweon_development")
        rows += field_study("field kweon_development", kweon_case, "kweon_development", out, a.quick,
                            a.reuse, log)
    log("DEM: the nip of kawamoto_nip (small)")
    rows += dem_study("nip (kawamoto_nip small)", nip_case, NIP_SCENE, NIP_REFERENCE, NIP_KNOBS,
                      NIP_OBSERVABLES, out, a.quick, a.threads, a.reuse, log, repeats)
    log("DEM: the development cell (Kweon's scene)")
    rows += dem_study("development cell (Kweon)", cell_case, DEVELOPMENT_SCENE, DEVELOPMENT_REFERENCE, DEVELOPMENT_KNOBS,
                      DEVELOPMENT_OBSERVABLES, out, a.quick, a.threads, a.reuse, log, repeats)
    rows += not_measured_rows("development cell (Kweon)", "DMA [kg/m^2]")

    total = time.monotonic() - start
    csv_path = os.path.join(out, "pipeline_cost.csv")
    table.write_csv(csv_path, rows)
    header = ("magbrush pipeline error against cost (tools/bench --pipeline%s): a benchmark's output, "
              "one run, started %s on %s (%d cores, load average %.1f at the start), DEM on %d thread(s), "
              "%.0f s in all (this invocation: %.0f s). Wall times are of a shared machine: compare them as ratios."
              % (" --quick" if a.quick else "", started, platform.node(), os.cpu_count(), load[0], a.threads, sum(RUN_SECONDS), total))
    text = markdown(rows, header) + "".join("\n" + n for n in NOTES) + "\n"
    with open(os.path.join(out, "pipeline_cost.md"), "w") as f:
        f.write(text)
    print(text)
    try:
        plot(rows, os.path.join(out, "pipeline_cost.png"))
    except ImportError as e:
        print("no figure (%s)" % e)
    print("outputs: %s, pipeline_cost.md, pipeline_cost.png in %s" % (csv_path, out))


if __name__ == "__main__":
    main()
