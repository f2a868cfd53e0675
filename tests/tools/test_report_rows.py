"""Rows of the run report (tools/report.py) from synthetic measurement files: the steady-state
verdict, the particle budget and the closed sump of a fed scene, the nip window's budget, the
nip's key numbers (none when the averaging window held no sample). Stdlib only, so any Python 3
runs it."""

import math
import os
import sys
import tempfile
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


class SymmetryRows(unittest.TestCase):
    """The nip's asymmetry with its standard errors, from dem/summary.csv's rows."""

    @staticmethod
    def row(key, value, se):
        return {"key": key, "value": repr(value), "standard_error": repr(se)}

    def test_centroid_against_spread_and_the_side(self):
        rows = report.symmetry_rows([self.row("pressure_centroid_m", -0.76e-3, 0.05e-3),
                                     self.row("pressure_spread_m", 0.72e-3, 0.02e-3),
                                     self.row("pressure_upstream_over_downstream", 3.1, 0.2),
                                     self.row("touching_centroid_m", -0.4e-3, 0.03e-3),
                                     self.row("touching_upstream_over_downstream", 1.4, 0.1)])
        self.assertEqual(len(rows), 3)
        self.assertIn("-0.76 ± 0.05 mm", rows[0][1])
        self.assertTrue(rows[0][3].startswith("centroid 1.1 × the spread, upstream"), rows[0])
        self.assertIn("3.1 ± 0.2", rows[1][1])

    def test_no_rows_without_the_measurement(self):
        self.assertEqual(report.symmetry_rows([]), [])
        self.assertEqual(report.symmetry_rows(None), [])


class DevelopmentWindow(unittest.TestCase):
    """The toner development plot's window: where averaging starts and the halves it compares."""

    def test_the_file_states_where_averaging_starts(self):
        import tempfile
        with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
            f.write("# toner on the drum ...; the means average the rows from t = 0.02 s\ntime_s,tma_kg_per_m2\n")
        try:
            self.assertEqual(report.averaging_start(f.name), 0.02)
            with open(f.name, "w") as g:
                g.write("# toner on the drum ... (an earlier version)\ntime_s,tma_kg_per_m2\n")
            self.assertEqual(report.averaging_start(f.name), 0.0)
        finally:
            os.unlink(f.name)

    def test_halves_are_the_window_split_by_count_without_nan(self):
        t = [0, 1, 2, 3, 4, 5, 6, 7]
        v = [9.0, 9.0, 1.0, math.nan, 2.0, 3.0, 4.0, 6.0]
        window, halves = report.window_halves(t, v, 2)
        self.assertEqual([ti for ti, _ in window], [2, 4, 5, 6, 7])
        self.assertEqual(halves, [(2, 4, 1.5), (5, 7, (3.0 + 4.0 + 6.0) / 3)])
        self.assertEqual(report.window_halves(t, v, 6)[1], [])  # two samples: no halves

    def test_period_halves_are_the_older_and_the_newer_whole_periods(self):
        # Three periods: the older half holds one, the newer two (as the summary's drift).
        halves = report.period_halves([20.0, 27.5, 35.0], [27.5, 35.0, 42.5], [2.0, 3.0, 5.0])
        self.assertEqual(halves, [(20.0, 27.5, 2.0), (27.5, 42.5, 4.0)])
        self.assertEqual(report.period_halves([20.0], [27.5], [2.0]), [])  # one period: no halves


def summary(drift_nf, se_nf, resolution, significant, reached):
    """dem/summary.csv rows as report.py reads them (one tested mean)."""
    return [{"key": "normal_force_per_length_N_m", "value": "0.53", "drift": repr(drift_nf),
             "drift_standard_error": repr(se_nf), "meaning": "normal force"},
            {"key": "steady_state", "value": "1" if reached else "0", "drift": "nan",
             "meaning": f"{1 if reached else 0} of 1 tested means drift < 2 % between the halves of their window"},
            {"key": "significant_drift", "value": "1" if significant else "0", "drift": "nan", "meaning": ""},
            {"key": "drift_resolution", "value": repr(resolution), "drift": "nan", "meaning": ""}]


class SteadyStateRow(unittest.TestCase):
    def test_undecided_says_how_much_longer(self):
        # Resolution 4 % against a 2 % tolerance: block errors fall as 1/sqrt(window), so 4x.
        row = report.steady_state_rows(summary(0.025, 0.017, 0.04, False, False))[0]
        self.assertTrue(row[1].startswith("undecided"), row)
        self.assertIn("~4.0× this window", row[3])

    def test_a_placed_load_is_told_to_deepen_the_slab(self):
        # Nothing supplied: the load drains, so more samples must come from a deeper slab.
        row = report.steady_state_rows(summary(0.025, 0.017, 0.04, False, False), supplied=False)[0]
        self.assertIn("(a deeper slab: nothing is supplied", row[3])
        self.assertNotIn("a longer run, or", row[3])

    def test_a_trend_is_not_a_matter_of_samples(self):
        row = report.steady_state_rows(summary(0.10, 0.02, 0.04, True, False))[0]
        self.assertTrue(row[1].startswith("NOT reached"), row)
        self.assertNotIn("this window (a longer run", row[3])

    def test_the_drift_says_which_way(self):
        # A falling mean (negative drift) is as far from steady as a rising one, and the row
        # says it falls.
        row = report.steady_state_rows(summary(-0.10, 0.02, 0.04, True, False))[0]
        self.assertTrue(row[1].startswith("NOT reached"), row)
        self.assertIn("normal_force_per_length_N_m -10.0 %", row[3])

    def test_reached_needs_no_advice(self):
        row = report.steady_state_rows(summary(0.005, 0.004, 0.008, False, True))[0]
        self.assertEqual(row[1], "reached")
        self.assertNotIn("× this window", row[3])


    def test_a_state_value_is_named_first_and_the_resolution_qualifies_reached(self):
        # The nip: the beads in its window hold (+0.4 %), the drum force fluctuates (-4.4 %
        # within its noise); the run's verdict is "reached", and the row says what that means
        # for the forces when the window resolves less than 2 %.
        rows = summary(-0.044, 0.025, 0.05, False, True)
        rows.insert(0, {"key": "beads_in_nip_window", "value": "3960", "drift": "0.004",
                        "drift_standard_error": "0.001", "meaning": "beads", "state": "1"})
        rows[-3]["meaning"] = ("1 of 1 state values (beads held) drift < 2 % between the halves of their window; "
                               "0 of 1 other tested means drift beyond both that and two standard errors")
        row = report.steady_state_rows(rows)[0]
        self.assertEqual(row[1], "reached")
        self.assertTrue(row[3].startswith("drift: beads_in_nip_window +0.4 %, normal_force_per_length_N_m -4.4 %"),
                        row)
        self.assertIn("no trend beyond that, not a 2 % certainty", row[3])


class BudgetRow(unittest.TestCase):
    def test_budget_closes(self):
        f = flow([10, 11], [0, 3], [0, 2], [1e-6, 1.1e-6], [math.nan, math.nan])
        self.assertEqual(report.budget_row(f)[3], "conserved")

    def test_a_lost_particle_shows(self):
        f = flow([10, 10], [0, 3], [0, 2], [1e-6, 1.1e-6], [math.nan, math.nan])
        self.assertEqual(report.budget_row(f)[3], "NOT conserved")


def nip_series(inside, entered, left):
    return {"time_s": ["0", "1e-3"], "in_window": [str(v) for v in inside],
            "entered": ["0", str(entered)], "left": ["0", str(left)]}


class WindowBudgetRow(unittest.TestCase):
    def test_a_window_between_inflow_and_outflow_closes(self):
        self.assertEqual(report.window_budget_row(nip_series([3765, 3911], 3626, 3480))[3], "holds")

    def test_an_outflow_inside_the_window_shows(self):
        # 20 beads removed inside the window never crossed its downstream edge.
        row = report.window_budget_row(nip_series([3765, 3891], 3626, 3480))
        self.assertTrue(row[3].startswith("does NOT hold (off by -20)"), row)


def nip_summary(samples, t_from, t_to, peak):
    """nip_summary.csv as report.read_summary returns it: {key: (value, unit)}."""
    return {"samples": (float(samples), "1"), "t_from": (t_from, "s"), "t_to": (t_to, "s"),
            "relative_surface_speed": (0.1348, "m/s"), "slip_at_gap_centre": (0.12, "m/s"),
            "peak_normal_pressure": (peak, "Pa"), "normal_force_per_length": (0.62, "N/m")}


class NipRows(unittest.TestCase):
    """The nip's key numbers: means over the averaging window, or nothing when it held no sample."""

    def test_no_samples_gives_no_numbers(self):
        # A run shorter than nip.average_from: the engine writes 0 samples and NaN times; the
        # report must not print "0 kPa averaged over 0 samples, t = nan .. nan ms".
        rows = report.key_numbers(nip_summary(0, math.nan, math.nan, math.nan), None, None, None)
        self.assertEqual([r[1] for r in rows], ["no samples in the averaging window"], rows)
        # What older engines wrote (t = -1 s, a peak of 0 Pa) reads the same.
        rows = report.key_numbers(nip_summary(0, -1.0, -1.0, 0.0), None, None, None)
        self.assertEqual([r[1] for r in rows], ["no samples in the averaging window"], rows)
        self.assertFalse(any("kPa" in r[1] for r in rows), rows)

    def test_samples_give_the_window(self):
        rows = report.key_numbers(nip_summary(25000, 0.025, 0.075, 360.0), None, None, None)
        self.assertIn(("averaged over", "25000 samples, t = 25 .. 75 ms", "", ""), rows)
        self.assertTrue(any(r[0] == "peak normal pressure on the drum" for r in rows), rows)



class DecisionPage(unittest.TestCase):
    """What makes the report a page to decide from: errors, bounds, windows, sparse bins, inputs."""

    def test_a_one_contact_edge_bin_is_masked(self):
        # The default nip's 1 ms run: an edge bin touched once (175 uN) among bins of hundreds.
        profile = {"x_mm": [-2.5, -2.25, -2.0, 0.0], "contact_samples": [1, 82, 300, 0]}
        self.assertEqual(report.sparse_bins(profile, 251), [True, False, False, False])
        self.assertEqual(report.sparse_bins({"x_mm": [0.0]}, 251), [False])  # no counts: nothing masked

    def test_key_numbers_carry_their_standard_errors_and_bounds(self):
        rows = [{"key": "dma_kg_per_m2", "value": "0.31", "standard_error": "0.012", "unit": "kg/m^2",
                 "meaning": "DMA"},
                {"key": "dma_kg_per_m2_bound", "value": "0.6", "standard_error": "nan", "unit": "kg/m^2",
                 "meaning": "bulk"},
                {"key": "peak_normal_pressure_Pa", "value": "360", "standard_error": "nan", "unit": "Pa",
                 "meaning": "peak"}]
        self.assertEqual(report.with_error(rows, "dma_kg_per_m2", 0.31), "0.31 ± 0.012")
        self.assertEqual(report.with_error(rows, "peak_normal_pressure_Pa", 360.0, 1e-3), "0.36")
        every = report.all_key_numbers(rows)
        self.assertEqual([r[0] for r in every], ["dma_kg_per_m2", "peak_normal_pressure_Pa"])
        self.assertEqual(every[0][3], "0.6")  # the bound beside its key, not a row of its own

    def test_windows_and_inputs_come_from_the_resolved_case(self):
        import tempfile
        with tempfile.TemporaryDirectory() as d:
            dem = os.path.join(d, "dem")
            os.makedirs(dem)
            for name in ("nip_profile.csv", "flow_report.csv"):
                open(os.path.join(dem, name), "w").close()
            resolved = os.path.join(d, "case_resolved.txt")
            with open(resolved, "w") as f:
                f.write("# case\nname = nip\ndrum.gap = 400 um\nroller.poles.S1.angle = 0 deg\n"
                        "roller.poles.S1.shape_factor = 10 rad^-2\nnip.average_from = 25 ms\n"
                        "flow_report.average_from = 500 us\ndevelopment.average_from = 3 ms\n")
            self.assertEqual(report.averaging_windows(dem, resolved), [("nip", 0.025), ("flow report", 0.0005)])
            keys = [k for k, _ in report.inputs_table(resolved)]
            self.assertIn("drum.gap", keys)
            self.assertIn("roller.poles.S1.angle", keys)
            self.assertNotIn("roller.poles.S1.shape_factor", keys)

class DesignSection(unittest.TestCase):
    """The design of the poles in the run report: linked from <run folder>/design/, its requirements shown."""

    def test_a_run_folder_without_a_design_has_no_section(self):
        with tempfile.TemporaryDirectory() as run:
            self.assertIsNone(report.design_section(run, os.path.join(run, "report")))

    def test_the_design_page_is_linked_with_its_requirements(self):
        with tempfile.TemporaryDirectory() as run:
            os.makedirs(os.path.join(run, "design"))
            open(os.path.join(run, "design", "index.html"), "w").write("<html></html>")
            open(os.path.join(run, "design", "design_requirements.csv"), "w").write(
                "requirement,kind,unit,target,tolerance,value_ring,met_ring,miss_ring,value_fem,met_fem,miss_fem\n"
                '"S2 peak |Bn|",equal,mT,50,10,50.0012,1,-9.9988,49.2,1,-9.2\n'
                '"release somewhere on 185.0–200.0°",at_least,g,0.5,0,0.41,0,0.09,0.40,0,0.1\n')
            d = report.design_section(run, os.path.join(run, "report"))
            self.assertEqual(d["page"], os.path.join("..", "design", "index.html"))
            self.assertIsNone(d["image"])
            self.assertEqual(d["rows"][0], ("S2 peak |Bn|", "50 ± 10 mT (equal)", "50.0012", "met", "49.2", "met"))
            self.assertEqual(d["rows"][1][3], "MISSED")
            self.assertEqual(d["rows"][1][5], "MISSED")


if __name__ == "__main__":
    unittest.main()
