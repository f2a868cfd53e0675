"""`magbrush compare` (tools/compare.py) on two synthetic run folders: the page's numbers are
each run's own summary.csv figures, the difference is judged against the combined standard
error, the inputs that differ are listed without the folders' own names, and the driver
refuses a folder that holds no finished run. Stdlib only (the plots are drawn only where
matplotlib is installed). With the path of the built `magbrush` as first argument it also
runs the subcommand itself."""

import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
import compare  # noqa: E402

MAGBRUSH = None  # set from the command line


def make_run(root, name, rows, inputs, overrides=()):
    """A run folder as `magbrush run` leaves it: dem/summary.csv, case_resolved.txt, variant.txt
    and a nip profile."""
    run = os.path.join(root, "results", name)
    os.makedirs(os.path.join(run, "dem"))
    with open(os.path.join(run, "dem", "summary.csv"), "w") as f:
        f.write("# magbrush run summary (synthetic)\n")
        f.write("key,value,standard_error,drift,unit,meaning,measurement,drift_standard_error,state\n")
        for key, value, se in rows:
            f.write(f"{key},{value!r},{se!r},nan,N/m,{key} meaning,test,nan,0\n")
    with open(os.path.join(run, "case_resolved.txt"), "w") as f:
        f.write(f"# case {name}\n")
        for k, v in inputs.items():
            f.write(f"{k:30s} = {v}\n")
        f.write(f"output.directory               = results/{name}\n")
        f.write(f"field.output_dir               = results/{name}/fields\n")
    with open(os.path.join(run, "variant.txt"), "w") as f:
        f.write("# synthetic\ncase cases/x.yaml\n" + "".join(f"set {o}\n" for o in overrides))
    with open(os.path.join(run, "dem", "nip_profile.csv"), "w") as f:
        f.write("# synthetic\nx_mm,slip_speed_m_s,normal_pressure_Pa,density_per_mm2,contact_samples\n")
        for x in (-1.0, 0.0, 1.0):
            f.write(f"{x},0.1,{100 + 10 * x},40,{1 if x > 0 else 50}\n")
    return run


def read_compare_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class CompareTwoRuns(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix="magbrush_compare_")
        self.a_rows = [("normal_force_per_length_N_m", 0.624, 0.011), ("touching_beads", 71.8, 1.0),
                       ("peak_normal_pressure_Pa", 360.0, math.nan)]
        self.b_rows = [("normal_force_per_length_N_m", 1.19, 0.02), ("touching_beads", 72.5, 1.2),
                       ("peak_normal_pressure_Pa", 410.0, math.nan), ("only_in_b", 3.0, 0.5)]
        self.a = make_run(self.root, "nip", self.a_rows, {"name": "nip", "drum.gap": "400 um", "dem.seed": "1"})
        self.b = make_run(self.root, "nip-1a2b3c", self.b_rows, {"name": "nip", "drum.gap": "300 um", "dem.seed": "1"},
                          ["drum.gap=0.3mm"])
        self.out = os.path.join(self.root, "cmp")

    def tearDown(self):
        shutil.rmtree(self.root, ignore_errors=True)

    def test_numbers_equal_each_runs_summary_and_are_judged(self):
        self.assertEqual(compare.main(["--out", self.out, self.a, self.b]), 0)
        rows = read_compare_csv(os.path.join(self.out, "compare.csv"))
        got = {(r["key"], r["run"]): r for r in rows}
        for run, table in ((self.a, self.a_rows), (self.b, self.b_rows)):
            for key, value, se in table:
                r = got[(key, run)]
                self.assertEqual(float(r["value"]), value, key)
                if math.isnan(se):
                    self.assertTrue(math.isnan(float(r["standard_error"])), key)
                else:
                    self.assertEqual(float(r["standard_error"]), se, key)
        force = got[("normal_force_per_length_N_m", self.b)]
        self.assertAlmostEqual(float(force["difference_from_first"]), 1.19 - 0.624, places=12)
        self.assertAlmostEqual(float(force["combined_standard_error"]), math.hypot(0.011, 0.02), places=12)
        self.assertEqual(force["verdict"], "beyond")
        self.assertEqual(got[("touching_beads", self.b)]["verdict"], "within")  # 0.7 < 2 x 1.56
        self.assertEqual(got[("peak_normal_pressure_Pa", self.b)]["verdict"], "no error")
        self.assertEqual(got[("only_in_b", self.b)]["verdict"], "absent in the first run")
        self.assertEqual(got[("normal_force_per_length_N_m", self.a)]["verdict"], "reference")

        with open(os.path.join(self.out, "index.html")) as f:
            page = f.read()
        self.assertIn("0.624 ± 0.011", page)
        self.assertIn("1.19 ± 0.02", page)
        self.assertIn("beyond the combined error", page)
        self.assertIn("drum.gap=0.3mm", page)  # the variant's overrides
        self.assertIn("case_resolved.txt", page)  # linked

    def test_inputs_that_differ_leave_out_the_folders(self):
        runs = [compare.Run(self.a), compare.Run(self.b)]
        self.assertEqual(compare.differing_inputs(runs), [("drum.gap", ["400 um", "300 um"])])

    def test_the_threshold_is_two_combined_standard_errors(self):
        self.assertEqual(compare.difference((1.0, 0.3), (1.0 + 2 * math.hypot(0.3, 0.4) * 1.001, 0.4))[2], "beyond")
        self.assertEqual(compare.difference((1.0, 0.3), (1.0 + 2 * math.hypot(0.3, 0.4) * 0.999, 0.4))[2], "within")

    def test_a_folder_without_a_finished_run_is_refused(self):
        empty = os.path.join(self.root, "results", "empty")
        os.makedirs(empty)
        self.assertEqual(compare.main(["--out", self.out, self.a, empty]), 2)

    def test_a_moved_pole_shows_as_the_shift_of_its_flux_peak(self):
        def profile(run, name, shift_deg):
            folder = os.path.join(run, "fields")
            os.makedirs(folder, exist_ok=True)
            with open(os.path.join(folder, name + "_profile_sleeve.csv"), "w") as f:
                f.write("# synthetic\nangle_deg,Bn_T,Bt_T\n")
                for k in range(1440):
                    a = 0.25 * k
                    d1 = (a - shift_deg + 180.0) % 360.0 - 180.0  # the moved south pole near 0 deg
                    d2 = (a - 180.0 + 180.0) % 360.0 - 180.0      # a north pole at 180 deg, not moved
                    f.write(f"{a},{-0.1 * math.exp(-(d1 / 10) ** 2) + 0.07 * math.exp(-(d2 / 10) ** 2)},0\n")
        profile(self.a, "nip", 0.0)
        profile(self.b, "nip", 3.0)
        rows = compare.peak_shifts([compare.Run(self.a), compare.Run(self.b)])
        self.assertEqual(len(rows), 2, rows)
        by_angle = {round(angle): others[0] for angle, _, others in rows}
        self.assertAlmostEqual(by_angle[0][0], 3.0, places=6)  # the south pole moved 3 deg
        self.assertAlmostEqual(by_angle[180][0], 0.0, places=6)
        self.assertEqual(compare.main(["--out", self.out, self.a, self.b]), 0)
        with open(os.path.join(self.out, "index.md")) as f:
            self.assertIn("+3.00 deg", f.read())

    @unittest.skipIf(MAGBRUSH is None and len(sys.argv) < 2, "no magbrush binary given")
    def test_the_subcommand(self):
        binary = MAGBRUSH
        r = subprocess.run([binary, "compare", self.a, self.b, "-o", self.out], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertTrue(os.path.exists(os.path.join(self.out, "index.html")))
        rows = read_compare_csv(os.path.join(self.out, "compare.csv"))
        self.assertEqual(float([x for x in rows if x["key"] == "touching_beads" and x["run"] == self.b][0]["value"]),
                         72.5)
        missing = subprocess.run([binary, "compare", self.a, os.path.join(self.root, "nowhere")], capture_output=True,
                                 text=True)
        self.assertEqual(missing.returncode, 1)
        self.assertIn("holds no finished run", missing.stderr)
        one = subprocess.run([binary, "compare", self.a], capture_output=True, text=True)
        self.assertEqual(one.returncode, 2, one.stderr)


if __name__ == "__main__":
    if len(sys.argv) > 1 and not sys.argv[1].startswith("-"):
        MAGBRUSH = sys.argv.pop(1)
    unittest.main()
