"""The development threshold of a TMA study (tools/development_threshold.py): the line fit and its
error against exact lines and against the scatter of many noisy realisations. Stdlib only."""
import csv
import math
import os
import random
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))

import development_threshold as dt  # noqa: E402
import plot_sweep  # noqa: E402

BIASES = [-500.0, -600.0, -700.0, -800.0]


def tma(v, threshold=-300.0, sensitivity=1e-5):
    """A developer that develops in proportion to the bias beyond its threshold."""
    return sensitivity * (threshold - v)


class ExactLines(unittest.TestCase):
    def test_a_straight_line_gives_its_threshold_and_slope(self):
        fit = dt.fit_line(BIASES, [tma(v) for v in BIASES], [1e-4] * 4)
        x0, se = dt.zero_crossing(fit)
        self.assertAlmostEqual(x0, -300.0, delta=1e-9)
        self.assertAlmostEqual(fit["b"], -1e-5, delta=1e-17)
        self.assertLess(fit["chi2"], 1e-20)
        self.assertTrue(fit["weighted"])
        self.assertFalse(fit["scaled"])
        # The exact covariance of weighted least squares with equal errors s: var(b) = s² / Σ(x - x̄)².
        sxx = sum((v - sum(BIASES) / 4) ** 2 for v in BIASES)
        self.assertAlmostEqual(math.sqrt(fit["var_b"]), 1e-4 / math.sqrt(sxx), delta=1e-15)
        self.assertGreater(se, 0.0)

    def test_two_points_without_errors_give_the_threshold_but_no_error(self):
        fit = dt.fit_line(BIASES[:2], [tma(v) for v in BIASES[:2]])
        x0, se = dt.zero_crossing(fit)
        self.assertAlmostEqual(x0, -300.0, delta=1e-9)
        self.assertFalse(fit["weighted"])
        self.assertTrue(se != se)  # NaN: two points say nothing about the scatter

    def test_one_value_of_the_bias_is_no_line(self):
        self.assertIsNone(dt.fit_line([-800.0, -800.0], [1.0, 2.0]))


class NoisyRealisations(unittest.TestCase):
    def test_the_threshold_error_is_the_scatter_of_realisations(self):
        """4,000 studies with Gaussian noise of the stated standard error: the thresholds
        scatter as the fit's error predicts (within 5 %), about the true threshold."""
        sigma = 1.5e-4
        exact = dt.fit_line(BIASES, [tma(v) for v in BIASES], [sigma] * 4)
        _, predicted = dt.zero_crossing(exact)
        rng = random.Random(7)
        thresholds = []
        for _ in range(4000):
            ys = [tma(v) + rng.gauss(0.0, sigma) for v in BIASES]
            thresholds.append(dt.zero_crossing(dt.fit_line(BIASES, ys, [sigma] * 4))[0])
        mean = sum(thresholds) / len(thresholds)
        spread = math.sqrt(sum((t - mean) ** 2 for t in thresholds) / (len(thresholds) - 1))
        self.assertAlmostEqual(spread / predicted, 1.0, delta=0.05)
        self.assertLess(abs(mean + 300.0), 3 * spread / math.sqrt(len(thresholds)) + 0.01 * spread)

    def test_points_scattered_beyond_their_errors_widen_the_error(self):
        ys = [tma(v) for v in BIASES]
        ys[1] += 5e-4
        ys[2] -= 5e-4
        fit = dt.fit_line(BIASES, ys, [1e-5] * 4)
        self.assertTrue(fit["scaled"])
        unscaled = dt.fit_line(BIASES, [tma(v) for v in BIASES], [1e-5] * 4)
        self.assertAlmostEqual(fit["var_b"] / unscaled["var_b"], fit["chi2"] / fit["dof"], delta=1e-9)


class StudyTable(unittest.TestCase):
    header = ["point", "electric.bias", "electric.bias [V]", "tma_kg_per_m2", "tma_kg_per_m2_stderr",
              "tma_kg_per_m2_bound", "status"]

    def rows(self):
        out = []
        for v in BIASES:
            out.append([f"p{v:.0f}", f"{v:.0f}V", f"{v:g}", f"{tma(v):.9g}", "1e-4", f"{-4.4e-5 * v:.9g}", "ok"])
        out.append(["p-900", "-900V", "-900", "nan", "nan", f"{4.4e-5 * 900:.9g}", "failed"])
        return out

    def test_the_table_gives_the_threshold_and_the_contrast_zero(self):
        result = dt.study_threshold(self.header, self.rows())
        self.assertEqual(result["points"], 4)  # the failed point is left out
        self.assertAlmostEqual(result["threshold"], -300.0, delta=1e-6)
        self.assertAlmostEqual(result["slope"], -1e-5, delta=1e-15)
        self.assertAlmostEqual(result["contrast_zero"], 0.0, delta=1e-6)
        self.assertIn("threshold -300 ±", dt.describe(result))

    def test_a_study_of_something_else_has_no_threshold(self):
        header = ["point", "drum.gap", "drum.gap [m]", "dma_kg_per_m2"]
        self.assertIsNone(dt.study_threshold(header, [["p0", "0.4mm", "0.0004", "0.3"]]))

    def test_the_csv_holds_the_fit(self):
        result = dt.study_threshold(self.header, self.rows())
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "sweep_tma_threshold.csv")
            dt.write_csv(path, result)
            with open(path, newline="") as f:
                lines = [r for r in csv.reader(line for line in f if not line.startswith("#")) if r]
        self.assertEqual(lines[0], dt.COLUMNS)
        row = dict(zip(lines[0], lines[1]))
        self.assertAlmostEqual(float(row["threshold"]), -300.0, delta=1e-4)
        self.assertEqual(row["points"], "4")
        self.assertEqual(row["weighted"], "1")


class RecordingAxes:
    """What tools/plot_sweep.py draws, without matplotlib."""

    def __init__(self):
        self.lines, self.vertical = [], []

    def plot(self, xs, ys, *args, **kwargs):
        self.lines.append((list(xs), list(ys), kwargs.get("label", "")))

    def axvline(self, x, **kwargs):
        self.vertical.append(x)


class DrawnThreshold(unittest.TestCase):
    header = StudyTable.header

    def drawn(self, rows):
        ax = RecordingAxes()
        with tempfile.TemporaryDirectory() as d:
            xs = [float(r[2]) for r in rows]
            plot_sweep.draw_threshold(ax, d, self.header, rows, xs)
        return ax

    def test_a_threshold_near_the_points_is_drawn_down_to(self):
        ax = self.drawn(StudyTable().rows()[:4])
        (xs, ys, label), = ax.lines
        self.assertEqual(xs, [-800.0, -300.0])
        self.assertAlmostEqual(ys[1], 0.0, delta=1e-12)
        self.assertNotIn("off the axis", label)
        self.assertEqual(ax.vertical, [])  # zero contrast (0 V) lies beyond the line's reach

    def test_a_threshold_far_off_leaves_the_axis_to_the_points(self):
        # Two points whose line reaches zero at +538 V: drawn over the points' span and a fifth.
        rows = [["p0", "-500V", "-500", "2.08e-3", "", "2.2e-2", "ok"],
                ["p3", "-800V", "-800", "2.68e-3", "", "3.5e-2", "ok"]]
        ax = self.drawn(rows)
        (xs, _, label), = ax.lines
        self.assertEqual(xs, [-860.0, -440.0])
        self.assertIn("off the axis", label)
        self.assertEqual(ax.vertical, [])


if __name__ == "__main__":
    unittest.main()
