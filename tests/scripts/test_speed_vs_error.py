#!/usr/bin/python3
"""Tests of scripts/speed_vs_error with the real oprt binary ($OPRT_BINARY), on tiny frames.
The figures it reports are checked against what they must be, not against wall times."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "scripts", "speed_vs_error")
ROOM = os.path.join(REPO, "scenes", "paper_room.json")


class TestSpeedVsError(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([SCRIPT, *args, "--oprt", os.environ["OPRT_BINARY"]], capture_output=True, text=True)

    def test_tiny_run_reports_every_level_and_the_exact_cases_as_exact(self):
        with tempfile.TemporaryDirectory() as out:
            r = self.run_script(ROOM, "--resolution", "12x12", "--quanta", "10ns,100us", "--ius", "6", "--out", out)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(os.path.join(out, "timing.csv")) as f:
                rows = list(csv.DictReader(f))
            levels = [(row["arch"], row["level"], row["quantum"]) for row in rows]
            variants = [("contended", f"lt {v}", q) for v in ("calendar", "busy_until") for q in ("10ns", "100us")]
            self.assertEqual(levels, [(a, l, q) for a in ("ideal", "contended")
                                      for l, q in (("at", ""), ("lt", "10ns"), ("lt", "100us"), ("analytic", ""))]
                             + variants)
            for row in rows:
                # 12x12 primary rays, the same shadow rays at every level and architecture.
                self.assertEqual(row["rays"], rows[0]["rays"])
                self.assertGreater(int(row["rays"]), 144)
                if row["level"] == "at" or row["arch"] == "ideal":  # at itself; exact under ideal assumptions
                    self.assertEqual(float(row["makespan_err_pct"]), 0.0, row)
                    self.assertEqual(float(row["idle_err_l1_pct"]), 0.0, row)
            with open(os.path.join(out, "images.csv")) as f:
                images = {row["precision"]: row for row in csv.DictReader(f)}
            self.assertEqual(set(images), {"float", "double"})
            # The double render is the double reference bit for bit.
            self.assertEqual(int(images["double"]["id_mismatches"]), 0)
            self.assertEqual(float(images["double"]["color_rmse"]), 0.0)
            self.assertEqual(float(images["double"]["max_rel_z"]), 0.0)
            self.assertEqual(int(images["float"]["pixels"]), 144)
            self.assertLess(float(images["float"]["max_rel_z"]), 1e-4)
            with open(os.path.join(out, "speed_vs_error.md")) as f:
                self.assertIn("| paper_room | contended | lt | 100us |", f.read())
            self.assertGreater(os.path.getsize(os.path.join(out, "speed_vs_error.png")), 10000)

    def test_pipelined_units_are_exact_at_every_level_under_the_ideal_architecture(self):
        with tempfile.TemporaryDirectory() as out:
            r = self.run_script(ROOM, "--resolution", "12x12", "--quanta", "10ns,100us", "--ius", "6", "--iu", "pipelined",
                                "--no-variants", "--no-images", "--out", out)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            with open(os.path.join(out, "timing.csv")) as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(len(rows), 2 * 4)
            for row in rows:
                self.assertIn("--iu pipelined", row["command"])
                if row["arch"] == "ideal":
                    self.assertEqual(float(row["makespan_err_pct"]), 0.0, row)
                    self.assertEqual(float(row["idle_err_l1_pct"]), 0.0, row)
            with open(os.path.join(out, "speed_vs_error.md")) as f:
                self.assertIn("6 pipelined IUs", f.read())

    def test_bad_command_line_exits_2(self):
        r = self.run_script("/nonexistent.json")
        self.assertEqual(r.returncode, 2)
        self.assertIn("/nonexistent.json", r.stderr)
        r = self.run_script(ROOM, "--quanta", ",")
        self.assertEqual(r.returncode, 2)

    def test_a_failing_run_names_its_command(self):
        with tempfile.TemporaryDirectory() as out:
            r = self.run_script(ROOM, "--resolution", "8x8", "--quanta", "5parsec", "--no-images", "--out", out)
            self.assertEqual(r.returncode, 1)
            self.assertIn("--quantum 5parsec", r.stderr)
            self.assertIn("unknown time unit", r.stderr)


if __name__ == "__main__":
    sys.exit(unittest.main())
