"""The table logic of the pipeline's error-against-cost benchmark (tools/bench_pipeline.py).

One row per (scene, knob, setting, observable): the wall time of the stage the setting
affects, the observable's value, its value in the converged reference run and the relative
error between them. This module holds only the arithmetic and the selection rules, without
running anything, so that tests/tools/test_pipeline_cost_table.py can check them on a
synthetic table:

* relative error of a scalar: |value - reference| / |reference|; of a profile (the sleeve
  flux density against angle): the largest deviation over the profile divided by the
  profile's largest magnitude (an error of the peak-normalised profile, as the field
  solver's own check reports it);
* the noise of an observable: the largest relative change among repeats of the reference that
  differ only in the random seed (another realisation of the same scene). A knob that makes
  the DEM's trajectories diverge moves a measured mean by up to this much by chance alone, so
  an error at or below the noise is reported as "below noise", never as a small number;
* the cheapest setting of a knob within a tolerance: the fastest setting whose error is
  certified below the tolerance. An error below the noise only certifies "below the noise",
  so where the noise itself exceeds the tolerance no setting can be certified and the answer
  says so.

Stdlib only (csv, math): the test runs without numpy.
"""

import csv
import math

# The columns of pipeline_cost.csv, in order.
COLUMNS = ["scene", "knob", "setting", "is_reference", "stage", "wall_time_s", "observable",
           "value", "reference", "relative_error", "noise", "verdict"]

BELOW_NOISE = "below noise"
# The knob name of the reference's repeat with another seed (it measures the noise).
SEED_REPEAT = "seed repeat"


def relative_error(value, reference):
    """|value - reference| / |reference|; 0 when both are 0, inf when only the reference is."""
    if math.isnan(value) or math.isnan(reference):
        return math.nan
    if reference == 0.0:
        return 0.0 if value == 0.0 else math.inf
    return abs(value - reference) / abs(reference)


def profile_relative_error(values, references):
    """Largest |value - reference| over a profile sampled at the same points, divided by the
    largest |reference|."""
    if len(values) != len(references) or not references:
        raise ValueError("profiles of different lengths (%d, %d)" % (len(values), len(references)))
    peak = max(abs(r) for r in references)
    deviation = max(abs(v - r) for v, r in zip(values, references))
    if peak == 0.0:
        return 0.0 if deviation == 0.0 else math.inf
    return deviation / peak


def verdict(error, noise):
    """What the table prints for an error: the number, or "below noise" where the observable
    is noisy (noise > 0) and the error does not exceed the noise."""
    if math.isnan(error):
        return "not measured"
    if noise > 0.0 and error <= noise:
        return BELOW_NOISE
    return "%.3g" % error


def certified_error(error, noise):
    """The smallest error the run can vouch for: an error below the noise is only known to be
    below the noise."""
    return max(error, noise)


def cheapest_within(rows, tolerance):
    """The cheapest row (smallest wall_time_s) among rows of ONE knob and ONE observable whose
    certified error is within the tolerance, the reference included (its error is 0, its
    certified error the noise). Returns (row or None, reason): reason is "" with a row, else
    "noise above tolerance" (no setting, not even the reference's repeat, can be resolved to
    this tolerance) or "none tested reaches it"."""
    if not rows:
        return None, "none tested reaches it"
    noise = max(float(r["noise"]) for r in rows)
    if noise > tolerance:
        return None, "noise %.2g above tolerance" % noise
    within = [r for r in rows
              if certified_error(float(r["relative_error"]), float(r["noise"])) <= tolerance]
    if not within:
        return None, "none tested reaches it"
    return min(within, key=lambda r: float(r["wall_time_s"])), ""


def group(rows, *keys):
    """Rows grouped by the values of the given columns, in order of first appearance."""
    out = {}
    for r in rows:
        out.setdefault(tuple(r[k] for k in keys), []).append(r)
    return out


def selection_table(rows, tolerances=(1e-2, 1e-3)):
    """For every (scene, observable, knob): the cheapest setting within each tolerance, as
    dicts {scene, observable, knob, noise, tolerance -> text}. Every knob's rows include the
    reference setting (is_reference = 1, error 0), so a knob whose relaxed settings all fail
    keeps the reference setting; the seed repeat is the noise, not a knob."""
    measured = [r for r in rows if r["verdict"] != "not measured"]
    table = []
    for (scene, observable, knob), knob_rows in group(measured, "scene", "observable", "knob").items():
        if knob == SEED_REPEAT:
            continue
        entry = {"scene": scene, "observable": observable, "knob": knob,
                 "noise": max(float(r["noise"]) for r in knob_rows)}
        for tol in tolerances:
            best, reason = cheapest_within(knob_rows, tol)
            if best is None:
                entry[tol] = reason
            else:
                entry[tol] = "%s (%.3g s%s)" % (best["setting"], float(best["wall_time_s"]),
                                                ", the reference" if best["is_reference"] == "1" else "")
        table.append(entry)
    return table


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in COLUMNS})


def read_csv(path):
    with open(path, newline="") as f:
        return [dict(r) for r in csv.DictReader(f)]
