"""The development threshold of a TMA study: the bias at which the toner mass per area extrapolates
to zero, from a straight line through the study's points.

Above its threshold a two-component developer develops toner in proportion to the contrast
between the bias and the latent image, until the developed charge neutralises the contrast (the
neutralisation bound); below it the field cannot pull the toner off its carriers against their
adhesion. A printer engineer reads two numbers off TMA against bias: the threshold and the
slope (the developer's sensitivity, kg/m² per volt). This module fits

    TMA = a + b V

by weighted least squares (weights 1/σ² from the points' standard errors; unweighted, with the
scatter about the line as the error, when no point has one), and gives the threshold
V0 = -a/b with its standard error from the fit's covariance:

    var(V0) = (var(a) + V0² var(b) + 2 V0 cov(a, b)) / b².

With standard errors given, the covariance is scaled by χ²/dof when that exceeds 1 (the points
scatter more than their errors say: the line or the errors are not the whole story, and the
error bar says so); χ²/dof itself is reported, so a user sees whether a straight line fits.
The latent image's own threshold, where the contrast and so the bound vanish, comes from the
bound's line (exact: the bound is linear in the bias); the difference between the two is what
the developer adds (adhesion holding toner back, or toner developed by the fringe fields at zero
contrast).

Stdlib only: tests/tools/test_development_threshold.py runs it without matplotlib.
"""
import csv
import math
import os


def fit_line(xs, ys, sigmas=None):
    """Least-squares line y = a + b x. Returns a dict with a, b, var_a, var_b, cov_ab, chi2,
    dof, weighted (bool), scaled (bool: covariance scaled by chi2/dof); None with fewer than two
    distinct x. sigmas: the points' standard errors; weighted only when every one is finite
    and positive."""
    n = len(xs)
    if n < 2 or len(set(xs)) < 2:
        return None
    weighted = sigmas is not None and all(s == s and s > 0 for s in sigmas)
    w = [1.0 / (s * s) for s in sigmas] if weighted else [1.0] * n
    S = sum(w)
    Sx = sum(wi * x for wi, x in zip(w, xs))
    Sy = sum(wi * y for wi, y in zip(w, ys))
    Sxx = sum(wi * x * x for wi, x in zip(w, xs))
    Sxy = sum(wi * x * y for wi, x, y in zip(w, xs, ys))
    delta = S * Sxx - Sx * Sx
    b = (S * Sxy - Sx * Sy) / delta
    a = (Sxx * Sy - Sx * Sxy) / delta
    chi2 = sum(wi * (y - a - b * x) ** 2 for wi, x, y in zip(w, xs, ys))
    dof = n - 2
    var_a, var_b, cov_ab = Sxx / delta, S / delta, -Sx / delta
    scale = 1.0
    if not weighted:
        # No errors given: the scatter about the line is the error (none from two points).
        scale = chi2 / dof if dof > 0 else float("nan")
    elif dof > 0 and chi2 / dof > 1.0:
        scale = chi2 / dof
    return {"a": a, "b": b, "var_a": var_a * scale, "var_b": var_b * scale, "cov_ab": cov_ab * scale,
            "chi2": chi2, "dof": dof, "weighted": weighted, "scaled": weighted and scale > 1.0}


def zero_crossing(fit):
    """(x0, its standard error) where the fitted line crosses zero."""
    b = fit["b"]
    if b == 0:
        return float("nan"), float("nan")
    x0 = -fit["a"] / b
    var = (fit["var_a"] + x0 * x0 * fit["var_b"] + 2 * x0 * fit["cov_ab"]) / (b * b)
    return x0, math.sqrt(var) if var >= 0 else float("nan")


def number(text):
    try:
        return float(text)
    except ValueError:
        return float("nan")


def study_threshold(header, rows, key="tma_kg_per_m2", x_column="electric.bias [V]"):
    """The threshold of a study's table (sweep_summary.csv or sweep_mean.csv rows), or None
    when the table has no such key against that column or fewer than two usable points.
    Points whose value is not finite are left out (a failed point)."""
    col = {name: i for i, name in enumerate(header)}
    if key not in col or x_column not in col:
        return None
    points = []
    for r in rows:
        x, y = number(r[col[x_column]]), number(r[col[key]])
        s = number(r[col[key + "_stderr"]]) if key + "_stderr" in col else float("nan")
        if x == x and y == y:
            points.append((x, y, s))
    fit = fit_line([p[0] for p in points], [p[1] for p in points], [p[2] for p in points])
    if fit is None:
        return None
    x0, x0_se = zero_crossing(fit)
    result = {"key": key, "x_column": x_column, "points": len(points), "threshold": x0, "threshold_stderr": x0_se,
              "slope": fit["b"], "slope_stderr": math.sqrt(fit["var_b"]) if fit["var_b"] >= 0 else float("nan"),
              "intercept": fit["a"], "chi2_per_dof": fit["chi2"] / fit["dof"] if fit["dof"] > 0 else float("nan"),
              "weighted": fit["weighted"], "errors_scaled": fit["scaled"], "contrast_zero": float("nan")}
    if key + "_bound" in col:
        bound = [(number(r[col[x_column]]), number(r[col[key + "_bound"]])) for r in rows]
        bound = [(x, y) for x, y in bound if x == x and y == y]
        line = fit_line([x for x, _ in bound], [y for _, y in bound])
        if line is not None and line["b"] != 0:
            result["contrast_zero"] = -line["a"] / line["b"]
    return result


COLUMNS = ["key", "x_column", "points", "threshold", "threshold_stderr", "slope", "slope_stderr", "intercept",
           "chi2_per_dof", "weighted", "errors_scaled", "contrast_zero"]


def write_csv(path, result):
    """The fit as a one-row CSV (atomically), with a comment line that says what it is."""
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as f:
        f.write(f"# development threshold: {result['key']} = intercept + slope x over the study's points "
                f"(x = {result['x_column']}); threshold = where the line reaches zero, with its standard error; "
                "contrast_zero = where the physical bound (the latent image's contrast) vanishes\n")
        out = csv.writer(f)
        out.writerow(COLUMNS)
        out.writerow([f"{result[c]:.9g}" if isinstance(result[c], float) else
                      (int(result[c]) if isinstance(result[c], bool) else result[c]) for c in COLUMNS])
    os.replace(tmp, path)


def describe(result, unit="V"):
    """One line for a plot's legend."""
    chi = result["chi2_per_dof"]
    fit = f"χ²/dof {chi:.2g}" if chi == chi else "2 points: no scatter"
    return (f"line fit: threshold {result['threshold']:.0f} ± {result['threshold_stderr']:.0f} {unit}, "
            f"slope {result['slope']:.3g} ± {result['slope_stderr']:.2g} per {unit} ({fit})")
