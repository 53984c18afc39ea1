#!/usr/bin/python3
"""scripts/secondary_results (issue 29) on the real oprt: the BART museum at 16x12 pixels, depths 0
and 1, the three routes, the at check and the side-by-side pictures. Skipped without $OPRT_BINARY
or without the BART museum beside the repository (../shared/bart, read-only, never copied).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "scripts", "secondary_results")
MUSEUM = os.path.join(os.path.dirname(REPO), "shared", "bart", "museum", "museum5.aff")
OPRT = os.environ.get("OPRT_BINARY")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class TestArguments(unittest.TestCase):
    def test_an_unknown_scene_is_named(self):
        r = run("--scenes", "museum,attic", "--out", tempfile.gettempdir())
        self.assertEqual(r.returncode, 1)
        self.assertIn("secondary_results: --scenes: unknown attic", r.stderr)
        self.assertEqual(r.stdout, "")  # nothing printed before the check


@unittest.skipUnless(OPRT and os.path.isfile(MUSEUM), "needs OPRT_BINARY and ../shared/bart/museum")
class TestMuseum(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="secondary_results_test_")
        cls.rows_file = os.path.join(cls.dir, "rows.json")
        cls.result = run("--scenes", "museum", "--depths", "0:1", "--resolution", "16x12", "--oprt", OPRT,
                         "--out", os.path.join(cls.dir, "out"), "--json", cls.rows_file,
                         "--pictures", os.path.join(cls.dir, "pictures"), "--picture-resolution", "16x12")
        with open(cls.rows_file) as f:
            cls.rows = json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_a_row_per_depth_and_route(self):
        self.assertEqual(self.result.returncode, 0, self.result.stderr)
        self.assertEqual([(r["depth"], r["route"]) for r in self.rows],
                         [(d, route) for d in (0, 1) for route in ("broadcast", "multicast", "ordered")])
        table = [line for line in self.result.stdout.splitlines() if line.startswith("| museum |")]
        self.assertEqual(len(table), 6)

    def test_rays(self):
        for r in self.rows:
            self.assertEqual(r["rays"]["primary"], 16 * 12)  # one primary ray per pixel
            self.assertEqual(r["rays"]["refraction"], 0)  # the museum has no transmissive material
            self.assertAlmostEqual(r["rays_per_pixel"], sum(r["rays"].values()) / 192)
        self.assertEqual({r["rays"]["reflection"] for r in self.rows if r["depth"] == 0}, {0})  # depth 0: none
        # every route traces the same rays
        for d in (0, 1):
            self.assertEqual(len({json.dumps(r["rays"]) for r in self.rows if r["depth"] == d}), 1)

    def test_work_per_kind_adds_up_to_the_busy_cycles_and_broadcast_reaches_all(self):
        for r in self.rows:
            self.assertEqual(sum(r["work_cycles"].values()), r["busy_cycles"])
            if r["route"] == "broadcast":  # every ray to every one of the 32 units
                self.assertEqual({v for v in r["fanout_mean"].values() if v is not None}, {32.0})

    def test_the_at_level_agrees_at_the_deepest_depth(self):
        checks = [line for line in self.result.stdout.splitlines() if line.startswith("museum depth 1 ")]
        self.assertEqual(len(checks), 3)  # one per route
        self.assertTrue(all(line.endswith(": same") for line in checks), checks)

    def test_pictures_side_by_side(self):
        from PIL import Image
        path = os.path.join(self.dir, "pictures", "museum_depth0_depth1.png")
        self.assertEqual(Image.open(path).size, (2 * 16 + 4, 12))  # two 16x12 frames and a 4-pixel gap


if __name__ == "__main__":
    unittest.main()
