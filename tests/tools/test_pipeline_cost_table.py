"""The table logic of tools/bench_pipeline.py (tools/pipeline_cost_table.py) on synthetic rows:
relative errors of scalars and profiles, "below noise", and the cheapest setting of a knob
within a tolerance. Asserts the selection rules, never a timing."""

import math
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import pipeline_cost_table as table  # noqa: E402


def row(knob, setting, seconds, error, noise=0.0, reference=False, scene="s", observable="o"):
    return {"scene": scene, "knob": knob, "setting": setting, "is_reference": "1" if reference else "0",
            "stage": "dem", "wall_time_s": str(seconds), "observable": observable, "value": "1",
            "reference": "1", "relative_error": str(error), "noise": str(noise),
            "verdict": table.verdict(error, noise)}


class RelativeError(unittest.TestCase):
    def test_scalar(self):
        self.assertAlmostEqual(table.relative_error(1.02, 1.0), 0.02)
        self.assertAlmostEqual(table.relative_error(-0.98, -1.0), 0.02)
        self.assertEqual(table.relative_error(0.0, 0.0), 0.0)
        self.assertEqual(table.relative_error(1e-9, 0.0), math.inf)
        self.assertTrue(math.isnan(table.relative_error(math.nan, 1.0)))

    def test_profile_is_normalised_by_its_peak(self):
        # a deviation of 0.01 where the profile is small still counts against the peak of 0.1
        self.assertAlmostEqual(table.profile_relative_error([0.1, 0.011, -0.05], [0.1, 0.001, -0.05]), 0.1)
        with self.assertRaises(ValueError):
            table.profile_relative_error([1.0], [1.0, 2.0])


class Noise(unittest.TestCase):
    def test_verdict(self):
        self.assertEqual(table.verdict(0.01, 0.02), table.BELOW_NOISE)
        self.assertEqual(table.verdict(0.02, 0.02), table.BELOW_NOISE)
        self.assertEqual(table.verdict(0.03, 0.02), "0.03")
        self.assertEqual(table.verdict(1e-5, 0.0), "1e-05")  # a deterministic stage has no noise
        self.assertEqual(table.verdict(math.nan, 0.0), "not measured")


class Cheapest(unittest.TestCase):
    def test_cheapest_within_tolerance(self):
        rows = [row("k", "ref", 100, 0.0, reference=True), row("k", "a", 10, 0.05),
                row("k", "b", 20, 0.005), row("k", "c", 40, 0.0005)]
        best, reason = table.cheapest_within(rows, 1e-2)
        self.assertEqual((best["setting"], reason), ("b", ""))
        best, _ = table.cheapest_within(rows, 1e-3)
        self.assertEqual(best["setting"], "c")
        best, _ = table.cheapest_within(rows, 1e-4)
        self.assertEqual(best["setting"], "ref")  # only the reference itself

    def test_none_reaches_it_without_the_reference(self):
        best, reason = table.cheapest_within([row("k", "a", 10, 0.05)], 1e-2)
        self.assertIsNone(best)
        self.assertEqual(reason, "none tested reaches it")

    def test_noise_above_tolerance_certifies_nothing(self):
        rows = [row("k", "ref", 100, 0.0, noise=0.03, reference=True), row("k", "a", 10, 0.001, noise=0.03)]
        best, reason = table.cheapest_within(rows, 1e-2)
        self.assertIsNone(best)
        self.assertTrue(reason.startswith("noise"))
        # below noise, with the noise inside the tolerance: certified
        rows = [row("k", "ref", 100, 0.0, noise=0.004, reference=True), row("k", "a", 10, 0.001, noise=0.004)]
        self.assertEqual(table.cheapest_within(rows, 1e-2)[0]["setting"], "a")
        self.assertIsNone(table.cheapest_within(rows, 1e-3)[0])

    def test_selection_table_per_knob_and_observable(self):
        rows = [row("k", "ref", 100, 0.0, reference=True), row("k", "a", 10, 0.05), row("k", "b", 20, 0.002),
                row("j", "ref", 50, 0.0, reference=True), row("j", "x", 5, 0.0001),
                row(table.SEED_REPEAT, "seed=2", 100, 0.0), 
                row("k", "ref", 100, 0.0, reference=True, observable="p"), row("k", "a", 10, 0.2, observable="p")]
        sel = {(e["observable"], e["knob"]): e for e in table.selection_table(rows)}
        self.assertEqual(set(sel), {("o", "k"), ("o", "j"), ("p", "k")})  # the seed repeat is no knob
        self.assertTrue(sel[("o", "k")][1e-2].startswith("b (20 s"))
        self.assertTrue(sel[("o", "k")][1e-3].startswith("ref (100 s, the reference"))
        self.assertTrue(sel[("o", "j")][1e-3].startswith("x (5 s"))
        self.assertTrue(sel[("p", "k")][1e-2].startswith("ref"))

    def test_csv_round_trip(self):
        rows = [row("k", "a", 10, 0.05)]
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.csv")
            table.write_csv(path, rows)
            self.assertEqual(table.read_csv(path), rows)


if __name__ == "__main__":
    unittest.main()
