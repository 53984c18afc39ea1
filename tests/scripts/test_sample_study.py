#!/usr/bin/python3
"""scripts/sample_study and scripts/sample_screen (issue 37): the study's quick block on the real
oprt (four 128x128 cases, one seed, 1/16), and the screen's random configurations inside their
space. The study's runs skipped without $OPRT_BINARY."""
import csv
import os
import random
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from oprt.explore.space import load_space  # noqa: E402
from oprt.results import sample_screen  # noqa: E402

OPRT = os.environ.get("OPRT_BINARY")


class TestScreenConfigurations(unittest.TestCase):
    def test_every_value_inside_its_domain(self):
        space = load_space(os.path.join(REPO, "scripts", "examples", "explore_full.json"))
        rng = random.Random(3)
        for _ in range(200):
            config = sample_screen.random_config(space, rng)
            self.assertEqual(set(config), {p.name for p in space.params})
            for p in space.params:
                v = config[p.name]
                if p.kind == "choice":
                    self.assertIn(v, p.values)
                elif p.kind == "int":
                    self.assertTrue(p.lo <= v <= p.hi, (p.name, v))


@unittest.skipUnless(OPRT, "needs OPRT_BINARY")
class TestQuickStudy(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="sample_study_test_")
        cls.result = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "sample_study"), "--blocks", "quick",
                                     "--seeds", "1", "--fractions", "16", "--oprt", OPRT, "--out", cls.dir,
                                     "--plots", os.path.join(cls.dir, "plots")], capture_output=True, text=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_a_row_per_case_and_the_tables(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        with open(os.path.join(self.dir, "runs.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual([r["case"] for r in rows], [c[0] for c in sample_screen_cases()])
        for r in rows:
            self.assertEqual(r["fraction"], "1/16")
            self.assertIn(r["makespan_cycles_covered"], ("True", "False"))
            self.assertGreater(float(r["makespan_cycles_halfwidth"]), 0)
        self.assertIn("| 1/16 | 4 |", self.result.stdout)
        for png in ("error_by_fraction.png", "error_by_kind_1_16.png", "intervals_1_16.png"):
            self.assertTrue(os.path.isfile(os.path.join(self.dir, "plots", png)), png)


def sample_screen_cases():
    from oprt.results import sample_study
    return list(sample_study.quick_cases(tempfile.gettempdir()))


if __name__ == "__main__":
    unittest.main()
