"""Rows of the run report (tools/report.py) from synthetic measurement files: the particle
budget and the closed sump of a fed scene. Stdlib only, so any Python 3 runs it."""

import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import report  # noqa: E402


def flow(present, inflow, outflow, present_mass, sump):
    """flow_report.csv as report.py reads it: a dict of columns of strings."""
    return {"time_s": [str(1e-6 * k) for k in range(len(present))],
            "present": [str(v) for v in present], "in": [str(v) for v in inflow], "out": [str(v) for v in outflow],
            "present_mass_kg": [repr(v) for v in present_mass], "sump_mass_kg": [repr(v) for v in sump]}


class SumpRow(unittest.TestCase):
    def test_no_finite_sump_gives_no_row(self):
        # A fixed supply: the engine writes nan for the sump's stock; the report must not claim
        # a sump that is "NOT conserved (worst nan)".
        f = flow([10, 11], [0, 3], [0, 2], [1e-6, 1.1e-6], [math.nan, math.nan])
        self.assertIsNone(report.sump_row(f))

    def test_closed_sump_is_conserved(self):
        f = flow([10, 11], [0, 3], [0, 2], [1e-6, 1.1e-6], [2e-6, 1.9e-6])
        row = report.sump_row(f)
        self.assertIsNotNone(row)
        self.assertTrue(row[3].startswith("conserved"), row)

    def test_a_leak_is_reported(self):
        f = flow([10, 11], [0, 3], [0, 2], [1e-6, 1.1e-6], [2e-6, 2.0e-6])
        self.assertTrue(report.sump_row(f)[3].startswith("NOT conserved"))


class BudgetRow(unittest.TestCase):
    def test_budget_closes(self):
        f = flow([10, 11], [0, 3], [0, 2], [1e-6, 1.1e-6], [math.nan, math.nan])
        self.assertEqual(report.budget_row(f)[3], "conserved")

    def test_a_lost_particle_shows(self):
        f = flow([10, 10], [0, 3], [0, 2], [1e-6, 1.1e-6], [math.nan, math.nan])
        self.assertEqual(report.budget_row(f)[3], "NOT conserved")


if __name__ == "__main__":
    unittest.main()
