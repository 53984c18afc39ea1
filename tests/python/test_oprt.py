#!/usr/bin/python3
"""Unit tests of the oprt Python package (python/oprt), run by ctest, one entry per test class.

Every expected value is derived by hand in the comments beside it. TestRender needs the real
oprt ($OPRT_BINARY); the rest needs nothing but Python.
"""
import csv
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))

from oprt import files, pareto, rays, render, slurm, spec, stats, values  # noqa: E402

OPRT = os.environ.get("OPRT_BINARY")


def alive(pid):
    """Whether process `pid` exists and is not a zombie (a zombie has ended: only its entry remains)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def wait_until(condition, deadline_s=30.0):
    """Polls `condition` until it holds or `deadline_s` has passed; returns whether it held."""
    end = time.monotonic() + deadline_s
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


class TestPareto(unittest.TestCase):
    # Five points (x, y), both minimised:
    #   a (1, 5), b (2, 3), c (3, 4), d (4, 1), e (2, 6)
    # c is dominated by b (2 <= 3, 3 <= 4), e by a (1 <= 2, 5 <= 6) and by b; a, b, d: none is
    # as small as another in both. Front: a, b, d.
    POINTS = [(1, 5), (2, 3), (3, 4), (4, 1), (2, 6)]

    def test_front_of_five_points(self):
        self.assertEqual(pareto.front_indices(self.POINTS), [0, 1, 3])

    def test_front_of_dicts_sorted_by_x(self):
        pts = [{"x": x, "y": y, "name": n} for (x, y), n in zip(self.POINTS, "abcde")]
        self.assertEqual([p["name"] for p in pareto.pareto_front(list(reversed(pts)), "x", "y")], ["a", "b", "d"])

    def test_equal_points_do_not_dominate_each_other(self):
        # (1, 1) twice: neither is smaller in one objective, both stay; (1, 2) is dominated.
        self.assertEqual(pareto.front_indices([(1, 1), (1, 1), (1, 2)]), [0, 1])

    def test_dominates(self):
        self.assertTrue(pareto.dominates((1, 2, 3), (1, 2, 4)))
        self.assertFalse(pareto.dominates((1, 2, 3), (1, 2, 3)))
        self.assertFalse(pareto.dominates((0, 3), (1, 2)))


class TestHypervolume(unittest.TestCase):
    def test_two_objectives_by_hand(self):
        # Front a (1, 5), b (2, 3), d (4, 1) below ref (6, 6): slices along x,
        #   x in [1, 2): height 6 - 5 = 1        -> 1
        #   x in [2, 4): height 6 - 3 = 3        -> 6
        #   x in [4, 6): height 6 - 1 = 5        -> 10
        # total 17; the dominated points c (3, 4) and e (2, 6) add nothing.
        self.assertEqual(pareto.hypervolume(TestPareto.POINTS, (6, 6)), 17.0)

    def test_points_beyond_the_reference_add_nothing(self):
        # (7, 0) lies beyond x = 6; (1, 1) alone: 5 x 5 = 25.
        self.assertEqual(pareto.hypervolume([(1, 1), (7, 0)], (6, 6)), 25.0)
        self.assertEqual(pareto.hypervolume([], (1, 1)), 0.0)

    def test_three_objectives_by_hand(self):
        # Two boxes below ref (1, 1, 1): p (0.5, 0.5, 0) -> 0.5 * 0.5 * 1 = 0.25, and
        # q (0, 0, 0.5) -> 1 * 1 * 0.5 = 0.5; their intersection 0.5 * 0.5 * 0.5 = 0.125.
        # Union 0.25 + 0.5 - 0.125 = 0.625.
        self.assertAlmostEqual(pareto.hypervolume([(0.5, 0.5, 0.0), (0.0, 0.0, 0.5)], (1, 1, 1)), 0.625, places=15)

    def test_one_objective(self):
        self.assertEqual(pareto.hypervolume([(3,), (2,)], (10,)), 8.0)

    def test_agrees_with_optunas_wfg(self):
        try:
            import numpy as np
            from optuna._hypervolume import WFG
        except ImportError:
            self.skipTest("needs python3-optuna")
        import random
        rng = random.Random(5)
        pts = [[rng.random() for _ in range(3)] for _ in range(40)]
        self.assertAlmostEqual(pareto.hypervolume(pts, [1.0, 1.0, 1.0]),
                               float(WFG().compute(np.array(pts), np.ones(3))), places=12)


class TestPearson(unittest.TestCase):
    def test_known_series(self):
        # xs 1..5, ys 2 4 5 4 5: means 3 and 4; deviations -2 -1 0 1 2 and -2 0 1 0 1;
        # sxy = 4 + 0 + 0 + 0 + 2 = 6, sxx = 10, syy = 6: r = 6 / sqrt(60).
        self.assertAlmostEqual(stats.pearson([1, 2, 3, 4, 5], [2, 4, 5, 4, 5]), 6 / math.sqrt(60), places=15)

    def test_lines(self):
        self.assertAlmostEqual(stats.pearson([1, 2, 3], [10, 20, 30]), 1.0, places=15)
        self.assertAlmostEqual(stats.pearson([1, 2, 3], [3, 2, 1]), -1.0, places=15)

    def test_nan_where_undefined(self):
        # No spread: the correlation is undefined (0 / 0), not an error and not a number.
        self.assertTrue(math.isnan(stats.pearson([1, 2, 3], [5, 5, 5])))
        self.assertTrue(math.isnan(stats.pearson([7, 7], [1, 2])))
        # 0.1 three times: the mean is 0.10000000000000002 after rounding, but the series has no
        # spread: still NaN (a formula on the deviations alone would give +-1 or a huge number).
        self.assertTrue(math.isnan(stats.pearson([0.1, 0.1, 0.1], [1, 2, 3])))
        # A NaN in either series, and fewer than two points.
        self.assertTrue(math.isnan(stats.pearson([1, float("nan"), 3], [1, 2, 3])))
        self.assertTrue(math.isnan(stats.pearson([1], [2])))

    def test_unequal_lengths_are_an_error(self):
        with self.assertRaises(ValueError):
            stats.pearson([1, 2], [1, 2, 3])


class TestStatsFiles(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="oprt_package_test_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)

    def test_stats_json_from_a_folder_or_the_file(self):
        doc = {"units": 2, "area_mm2": {"total": 1.5},
               "frames": [{"frame": 0, "makespan_cycles": 1200, "ius": [{"busy_cycles": 700}, {"busy_cycles": 500}]}]}
        with open(os.path.join(self.dir, "stats.json"), "w") as f:
            json.dump(doc, f)
        for where in (self.dir, os.path.join(self.dir, "stats.json")):
            s = stats.read_stats(where)
            self.assertEqual(s["frames"][0]["makespan_cycles"], 1200)
            self.assertEqual(sum(u["busy_cycles"] for u in s["frames"][0]["ius"]), 1200)

    def test_stats_csv_numbers_become_numbers(self):
        with open(os.path.join(self.dir, "stats.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["frame", "iu", "busy", "parallel_efficiency", "energy_j", "fanout"])
            w.writerow([0, 0, 700, 0.5833333, "", "1 2"])
            w.writerow([0, 1, 500, 0.5833333, "", "3"])
        rows = stats.read_stats_csv(self.dir)
        self.assertEqual(len(rows), 2)
        self.assertEqual(rows[1]["busy"], 500)
        self.assertIsInstance(rows[1]["busy"], int)
        self.assertEqual(rows[0]["parallel_efficiency"], 0.5833333)
        self.assertEqual(rows[0]["energy_j"], "")  # empty stays empty (no energy without a technology)
        self.assertEqual(rows[0]["fanout"], "1 2")
        self.assertEqual(rows[1]["fanout"], 3)


class TestSlurm(unittest.TestCase):
    def test_exact_lines(self):
        text = slurm.array_script("oprt-sweep-s", ["first comment", "second"], 3, "/o/slurm", ["--time=00:10:00"],
                                  ["/r/scripts/sweep", "/r/my spec.json", "--out", "/o"], tail='--point "$SLURM_ARRAY_TASK_ID"')
        self.assertEqual(text.split("\n"), [
            "#!/bin/bash",
            "# first comment",
            "# second",
            "#SBATCH --job-name=oprt-sweep-s",
            "#SBATCH --array=0-2",
            "#SBATCH --ntasks=1",
            "#SBATCH --cpus-per-task=1",
            "#SBATCH --output=/o/slurm/%A_%a.log",
            "#SBATCH --time=00:10:00",
            "set -euo pipefail",
            ': "${SLURM_ARRAY_TASK_ID:?this is a Slurm array job: submit it with sbatch}"',
            'exec "${PYTHON:-/usr/bin/python3}" /r/scripts/sweep \'/r/my spec.json\' --out /o --point "$SLURM_ARRAY_TASK_ID" "$@"',
            ""])

    def test_refuses_to_run_outside_an_array_task(self):
        text = slurm.array_script("j", [], 1, "/tmp", [], ["-c", "pass"])
        env = {k: v for k, v in os.environ.items() if k != "SLURM_ARRAY_TASK_ID"}
        r = subprocess.run(["bash", "-c", text], capture_output=True, text=True, env=env)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("this is a Slurm array job", r.stderr)


class TestSpecAndFiles(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="oprt_package_test_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)

    def write(self, name, text):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def test_read_document_names_the_place(self):
        bad = [("[1]", "/: expected a JSON object"), ('{"format": "x/1", "extra": 1}', "/extra: unknown key (known: format, a)"),
               ('{"format": "x/2"}', '/format: expected "x/1", found "x/2"'), ("{", "line 1, column 2: not JSON: Expecting property name enclosed in double quotes")]
        for i, (text, message) in enumerate(bad):
            path = self.write(f"d{i}.json", text)
            with self.assertRaises(spec.SpecError) as e:
                spec.read_document(path, "x/1", ("format", "a"))
            self.assertEqual(str(e.exception), f"{path}: {message}")
        self.assertEqual(spec.read_document(self.write("ok.json", '{"format": "x/1", "a": 2}'), "x/1", ("format", "a")),
                         {"format": "x/1", "a": 2})

    def test_frames_as_text_and_bad_values(self):
        self.assertEqual(spec.check_value("frames", 3, "f", "/frames"), "3")
        with self.assertRaises(spec.SpecError) as e:
            spec.check_value("accel", "octree", "f", "/accel")
        self.assertEqual(str(e.exception), 'f: /accel: accel: unknown value "octree" (expected one of: brute, bvh)')

    def test_atomic_write_leaves_nothing_on_failure(self):
        path = os.path.join(self.dir, "out.txt")
        files.atomic_write(path, "first\n")

        def fail(f):
            f.write("half")
            raise RuntimeError("disk full")
        with self.assertRaises(RuntimeError):
            files.write_atomically(path, fail)
        with open(path) as f:
            self.assertEqual(f.read(), "first\n")
        self.assertEqual(os.listdir(self.dir), ["out.txt"])

    def test_csv_text_and_values(self):
        self.assertEqual(files.csv_text(["a", "b"], [{"a": 1, "b": "x,y"}]), 'a,b\n1,"x,y"\n')
        self.assertEqual(values.fmt_time(59), "0:59")
        self.assertEqual(values.fmt_time(3725), "1:02:05")  # 1 h, 2 min, 5 s
        self.assertFalse(values.is_integer(True))
        self.assertFalse(values.is_number(float("inf")))


class TestParentDeath(unittest.TestCase):
    """A child started by oprt.render.popen ends when its parent is killed with SIGKILL."""

    PARENT = ("import sys, time; sys.path.insert(0, sys.argv[1]); from oprt import render; "
              "p = render.popen(['sleep', '300']); print(p.pid, flush=True); time.sleep(300)")

    def test_child_ends_when_the_parent_is_killed_with_sigkill(self):
        parent = subprocess.Popen([sys.executable, "-c", self.PARENT, os.path.join(REPO, "python")],
                                  stdout=subprocess.PIPE, text=True)
        child = int(parent.stdout.readline())
        parent.stdout.close()
        self.assertTrue(alive(child))
        parent.kill()
        parent.wait()
        # The kernel sends the child SIGKILL as the parent ends; allow a loaded machine 30 s.
        self.assertTrue(wait_until(lambda: not alive(child), 30.0), f"child {child} still running 30 s after its parent")

    def test_a_parent_already_gone_is_noticed(self):
        # The request is made in the child after fork: if the parent had ended in between, the
        # child's parent is no longer the one noted, and the child signals itself.
        code = ("import sys, signal; sys.path.insert(0, sys.argv[1]); from oprt import render; "
                "render.die_with_parent(signal.SIGTERM, parent=2 ** 22 + 1)(); print('still here')")
        r = subprocess.run([sys.executable, "-c", code, os.path.join(REPO, "python")], capture_output=True, text=True)
        self.assertEqual(r.returncode, -signal.SIGTERM)
        self.assertEqual(r.stdout, "")


class TestRayKinds(unittest.TestCase):
    """oprt.rays on a hand-made frame: two units, three kinds with work, refraction without."""
    ARCH = {"costs": {"sphere": 9, "transform": 19, "node": 13, "box": 13, "box_setup": 12, "triangle": [4, 14, 17, 22],
                      "watertight": {"transform": 20, "triangle": [18, 20, 21, 27]}},
            "kernel": "moller", "iu": {"model": "serial"}}
    FRAME = {
        "rays": {"primary": 4, "shadow": 3, "reflection": 1},
        "ray_kinds": {"kinds": {
            "primary": {"rays": 4, "ray_bytes_per_ray": 52.0, "answer_bytes_per_ray": 64.25, "fanout_mean": 2.0},
            "shadow": {"rays": 3, "ray_bytes_per_ray": 52.0, "answer_bytes_per_ray": 32.0, "fanout_mean": 1.5},
            "reflection": {"rays": 1, "ray_bytes_per_ray": 52.0, "answer_bytes_per_ray": 0.0, "fanout_mean": 0.0}}},
        "ius": [{"work": {"primary": {"sphere_tests": 2, "transforms": 1, "node_tests": 3, "box_tests": 0, "box_setups": 1,
                                      "triangle_exit_stage": [1, 0, 0, 2]},
                          "shadow": {"sphere_tests": 1, "transforms": 1, "triangle_exit_stage": [0, 1, 0, 0]}}},
                {"work": {"reflection": {"sphere_tests": 1, "box_tests": 2, "triangle_exit_stage": [0, 0, 1, 0]}}}],
    }

    def stats(self, **arch):
        return {"arch": dict(self.ARCH, **arch)}

    def test_rays_of_every_kind(self):
        self.assertEqual(rays.rays(self.FRAME), {"primary": 4, "shadow": 3, "reflection": 1, "refraction": 0})

    def test_bus_bytes_are_the_ray_and_its_answers(self):
        # primary 52 + 64.25, shadow 52 + 32, reflection 52 + 0 (no unit answered), refraction: no ray
        self.assertEqual(rays.bus_bytes_per_ray(self.FRAME),
                         {"primary": 116.25, "shadow": 84.0, "reflection": 52.0, "refraction": None})
        self.assertEqual(rays.cells(rays.bus_bytes_per_ray(self.FRAME), "{:.2f}"), "116.25 / 84.00 / 52.00 / -")

    def test_work_priced_per_kind(self):
        # primary: 2 spheres x 9 + 1 transform x 19 + 3 nodes x 13 + 1 box setup x 12 + exits det 4, t 2 x 22 = 136
        # shadow: 9 + 19 + exit u 14 = 42; reflection (the other unit): 9 + 2 boxes x 13 + exit v 17 = 52
        self.assertEqual(rays.work_cycles(self.stats(), self.FRAME),
                         {"primary": 136, "shadow": 42, "reflection": 52, "refraction": 0})
        # watertight: transform 20, exits 18/20/21/27: primary 18 + 20 + 39 + 12 + 18 + 54 = 161,
        # shadow 9 + 20 + 20 = 49, reflection 9 + 26 + 21 = 56
        self.assertEqual(rays.work_cycles(self.stats(kernel="watertight"), self.FRAME),
                         {"primary": 161, "shadow": 49, "reflection": 56, "refraction": 0})

    def test_pipelined_units_are_refused(self):
        with self.assertRaises(ValueError):
            rays.work_cycles(self.stats(iu={"model": "pipelined"}), self.FRAME)


class TestPaths(unittest.TestCase):
    """Which oprt the package runs: in a checkout, and installed under a prefix."""

    def test_in_the_checkout_the_build_unless_told(self):
        env = dict(os.environ)
        env.pop("OPRT_BINARY", None)
        code = "from oprt import paths; print(paths.IN_CHECKOUT, paths.oprt_binary(), paths.oprt_binary('/x/oprt'))"
        out = subprocess.run([sys.executable, "-c", code], env=dict(env, PYTHONPATH=os.path.join(REPO, "python")),
                             capture_output=True, text=True, check=True).stdout.split()
        self.assertEqual(out, ["True", os.path.join(REPO, "build", "testbench", "oprt"), "/x/oprt"])
        env["OPRT_BINARY"] = "/y/oprt"
        out = subprocess.run([sys.executable, "-c", code], env=dict(env, PYTHONPATH=os.path.join(REPO, "python")),
                             capture_output=True, text=True, check=True).stdout.split()
        self.assertEqual(out[1], "/y/oprt")

    def test_installed_under_a_prefix_its_bin_oprt(self):
        """A copy of the package in PREFIX/lib/python3/dist-packages (cmake --install's layout)
        runs PREFIX/bin/oprt; without one there, `oprt` on PATH."""
        with tempfile.TemporaryDirectory() as prefix:
            site = os.path.join(prefix, "lib", "python3", "dist-packages")
            shutil.copytree(os.path.join(REPO, "python", "oprt"), os.path.join(site, "oprt"),
                            ignore=shutil.ignore_patterns("__pycache__"))
            code = "from oprt import paths; print(paths.IN_CHECKOUT, paths.oprt_binary())"
            env = {k: v for k, v in os.environ.items() if k != "OPRT_BINARY"}
            run = lambda path: subprocess.run([sys.executable, "-s", "-c", code], cwd=prefix, capture_output=True,
                                              text=True, check=True,
                                              env=dict(env, PYTHONPATH=site, PATH=path)).stdout.split()
            on_path = os.path.join(prefix, "elsewhere")
            os.makedirs(on_path)
            for folder in (on_path, os.path.join(prefix, "bin")):
                os.makedirs(folder, exist_ok=True)
                with open(os.path.join(folder, "oprt"), "w") as f:
                    f.write("#!/bin/sh\n")
                os.chmod(os.path.join(folder, "oprt"), 0o755)
            self.assertEqual(run("/usr/bin:/bin"), ["False", os.path.join(prefix, "bin", "oprt")])
            os.unlink(os.path.join(prefix, "bin", "oprt"))
            self.assertEqual(run(on_path + ":/usr/bin:/bin"), ["False", os.path.join(on_path, "oprt")])

    def test_chosen_scenes_and_script_arguments(self):
        self.assertEqual(render.chosen_scenes("a,c", ("a", "b", "c"), "t"), ["a", "c"])
        with self.assertRaises(SystemExit) as e:
            render.chosen_scenes("a,x,w", ("a", "b"), "t")
        self.assertEqual(str(e.exception.code), "t: --scenes: unknown w, x (known: a, b)")
        a = render.script_arguments("doc", "name", kitchen_resolution="1x1", level="at").parse_args(["--level", "lt"])
        self.assertEqual((a.kitchen_resolution, a.level, a.out), ("1x1", "lt", os.path.join(REPO, "out", "name")))


class TestInstall(unittest.TestCase):
    """python/ installs with Debian's pip, venv and setuptools, without the network (scripts/setup
    test installs them): python3 -m venv --system-site-packages v && v/bin/pip install
    --no-build-isolation --no-index ./python. Built from a copy, so that the checkout gets no
    build/ or egg-info."""

    def test_venv_install_without_the_network(self):
        with tempfile.TemporaryDirectory() as tmp:
            shutil.copytree(os.path.join(REPO, "python"), os.path.join(tmp, "python"),
                            ignore=shutil.ignore_patterns("__pycache__", "build", "*.egg-info"))
            env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "OPRT_BINARY")}
            step = lambda *cmd: subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True)
            for cmd in (("/usr/bin/python3", "-m", "venv", "--system-site-packages", "v"),
                        ("v/bin/pip", "install", "--no-build-isolation", "--no-index", "./python")):
                r = step(*cmd)
                self.assertEqual(r.returncode, 0, f"{' '.join(cmd)}:\n{r.stdout}{r.stderr}")
            r = step("v/bin/python", "-c", "import oprt, oprt.sweep.cli, oprt.explore.cli; from oprt import paths, pareto; "
                     "print(oprt.__file__, paths.IN_CHECKOUT, pareto.hypervolume([(1, 2), (2, 1)], (3, 3)))")
            self.assertEqual(r.returncode, 0, r.stderr)
            where, in_checkout, hv = r.stdout.split()
            # The environment's own copy; (1,2) and (2,1) below (3,3): 2 + 2 - 1 (their overlap) = 3.
            self.assertTrue(os.path.realpath(where).startswith(os.path.realpath(os.path.join(tmp, "v")) + os.sep), where)
            self.assertEqual((in_checkout, hv), ("False", "3.0"))
            r = step("v/bin/oprt-sweep", "--help")  # an entry point: scripts/sweep's usage
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("Architecture-exploration sweeps over `oprt render`", r.stdout)


@unittest.skipUnless(OPRT, "needs OPRT_BINARY (the real oprt)")
class TestRender(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="oprt_package_test_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)

    def test_render_returns_its_stats(self):
        out = os.path.join(self.dir, "room")
        s, wall = render.render([os.path.join(REPO, "scenes", "paper_room.json"), "--frames", "0", "--resolution", "8x8",
                                 "--level", "analytic"], out, OPRT, timed=True)
        self.assertGreater(wall, 0)
        self.assertEqual(len(s["frames"]), 1)
        self.assertEqual(s["frames"][0]["rays"]["primary"], 64)  # 8 x 8 pixels, one primary ray each
        rows = stats.read_stats_csv(out)
        self.assertEqual(len(rows), s["units"])  # one row per unit of the one frame
        self.assertEqual([r["busy"] for r in rows], [u["busy_cycles"] for u in s["frames"][0]["ius"]])

    def test_reference_returns_its_figures(self):
        out = os.path.join(self.dir, "ref")
        r = render.reference([os.path.join(REPO, "scenes", "paper_room.json"), "--frames", "0", "--resolution", "8x8",
                              "--depth", "0"], out, OPRT)
        self.assertEqual(r["frames"][0]["depth"], 0)
        self.assertEqual(r["frames"][0]["rays"]["primary"], 64)  # 8 x 8 pixels
        self.assertEqual(rays.rays(r["frames"][0])["reflection"], 0)  # depth 0: primary and shadow rays only
        self.assertTrue(os.path.isfile(os.path.join(out, "frame_0000.png")))

    def test_a_failed_render_ends_the_script_naming_it(self):
        with self.assertRaises(SystemExit) as e:
            render.render([os.path.join(self.dir, "none.json")], os.path.join(self.dir, "x"), OPRT, who="my_script")
        self.assertTrue(str(e.exception.code).startswith(f"my_script: {OPRT} render {self.dir}/none.json"),
                        e.exception.code)
        self.assertIn("failed (2)", str(e.exception.code))


if __name__ == "__main__":
    unittest.main()
