#!/usr/bin/python3
"""Tests of scripts/sweep and scripts/plot_sweep (run by ctest, one entry per test class).

Most tests drive a fake `oprt` (a small script that records its runs, can hang or fail on
request, and writes a stats.json); TestRealSweep uses the real binary from $OPRT_BINARY.
"""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SWEEP = os.path.join(REPO, "scripts", "sweep")
PLOT = os.path.join(REPO, "scripts", "plot_sweep")
ROOM = os.path.join(REPO, "scenes", "paper_room.json")
POLYGONS = os.path.join(REPO, "scenes", "paper_polygons.json")


def read(path):
    try:
        with open(path) as f:
            return f.read()
    except FileNotFoundError:  # a /proc entry that just went away
        return "- - Z"


sys.path.insert(0, os.path.join(REPO, "python"))
from oprt.sweep.points import load_spec  # noqa: E402  (scripts/sweep's SPEC reading)
from oprt.sweep.run import arch_doc, command  # noqa: E402

# A stand-in for oprt: appends "<out dir> <pid>" to $FAKE_OPRT_RUNS, then hangs (after writing a
# partial file) when --ius equals $FAKE_OPRT_HANG_IUS, fails with exit 2 when it equals
# $FAKE_OPRT_FAIL_IUS, and otherwise writes a minimal stats.json (with the --arch file's values).
FAKE_OPRT = r'''#!/usr/bin/python3
import json, os, sys, time
args = sys.argv[1:]
if "--check" in args:  # scripts/sweep asks before it runs anything: every point would run
    sys.exit(0)
opt = lambda name, default=None: args[args.index(name) + 1] if name in args else default
out, ius = opt("--out"), int(opt("--ius", "32"))
with open(os.environ["FAKE_OPRT_RUNS"], "a") as f:
    f.write(f"{os.path.basename(out)} {os.getpid()}\n")
if str(ius) == os.environ.get("FAKE_OPRT_HANG_IUS"):
    open(os.path.join(out, "partial.exr"), "w").write("half a frame")
    time.sleep(60)
if str(ius) == os.environ.get("FAKE_OPRT_FAIL_IUS"):
    print("oprt: fake failure for --ius", ius, file=sys.stderr)
    sys.exit(2)
arch = {"ius": ius, "balance": opt("--balance", "paper"), "subdivide": 1, "level": "at", "quantum_ns": 1000.0,
        "accel": "brute", "kernel": "moller", "precision": "float", "ray_fifo_depth": 0, "clock_mhz": 100.0,
        "bus": {"model": "ideal", "bytes_per_cycle": 8, "arbitration_cycles": 1},
        "memory": {"model": "ideal", "latency_cycles": 10, "bytes_per_cycle": 16},
        "gpp": {"cycles_per_ray": 0, "cycles_per_hit": 0},
        "costs": {"sphere": 9, "transform": 19, "triangle": [4, 14, 17, 22]}}
for key, value in json.load(open(opt("--arch"))).items():  # the generated architecture file
    if isinstance(value, dict):
        arch.setdefault(key, {}).update(value)
    elif key not in ("format", "comment"):
        arch[key] = value
makespan = 1000 // ius * (2 if opt("--balance") == "sa_n" else 1)  # sa_n: worse in every figure
unit = {"id": 0, "busy_cycles": 1000 // ius, "cycles": {"sphere": 1000 // ius, "transform": 0, "primitive": 0,
                                                      "idle": 0, "stall": 0}}
frame = {"frame": 0, "makespan_cycles": makespan, "parallel_efficiency": 1.0, "idle_fraction": 0.0,
         "busy_cycles": 1000, "wall_s": 0.01, "rays": {"primary": 4, "shadow": 0}, "rays_per_wall_s": 400,
         "bus": {"busy_cycles": 0, "bytes": 0, "transfers": 0}, "image_hash": "0", "ius": [unit] * ius,
         "frame_time_s": makespan * 1e-8, "energy_j": {"total": 1e-3 * (1 + ius / 10) * makespan * ius / 1000}}
json.dump({"arch": arch, "units": ius, "spheres": 32, "resolution": [2, 2], "frames": [frame],
           "tech": {"file": opt("--tech", "built in")}, "area_mm2": {"total": 1.0 * ius},
           "iu_arithmetic": {"adders": 1, "multipliers": 1}},
          open(os.path.join(out, "stats.json"), "w"))
'''


class SweepTestCase(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="oprt_sweep_test_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)
        self.out = os.path.join(self.dir, "out")
        self.fake = os.path.join(self.dir, "fake_oprt")
        with open(self.fake, "w") as f:
            f.write(FAKE_OPRT)
        os.chmod(self.fake, 0o755)
        self.runs_file = os.path.join(self.dir, "runs.txt")
        self.env = dict(os.environ, FAKE_OPRT_RUNS=self.runs_file)
        self.env.pop("FAKE_OPRT_HANG_IUS", None)
        self.env.pop("FAKE_OPRT_FAIL_IUS", None)

    def write_spec(self, spec, name="spec.json"):
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            json.dump({"format": "oprt-sweep/1", **spec}, f)
        return path

    def sweep(self, spec_file, *args, oprt=None, env=None):
        return subprocess.run([sys.executable, SWEEP, spec_file, "--out", self.out, "--oprt", oprt or self.fake, *args],
                              capture_output=True, text=True, env=env or self.env, timeout=300)

    def runs(self):
        """Directory name of each fake oprt run, in order."""
        if not os.path.exists(self.runs_file):
            return []
        with open(self.runs_file) as f:
            return [line.split()[0] for line in f]

    def read_csv(self, name):
        with open(os.path.join(self.out, name), newline="") as f:
            return list(csv.DictReader(f))


class TestGridExpansion(SweepTestCase):
    def test_cartesian_product_of_scenes_and_axes_in_spec_order(self):
        spec = self.write_spec({"scenes": [ROOM, POLYGONS], "frames": 3, "resolution": "8x8",
                                "grid": {"ius": [1, 2, 4], "balance": ["paper", "sa_n"]}})
        _, points = load_spec(spec)
        self.assertEqual(len(points), 2 * 3 * 2)
        self.assertEqual([(p["params"]["scene"], p["params"]["ius"], p["params"]["balance"]) for p in points],
                         [(s, n, b) for s in (ROOM, POLYGONS) for n in (1, 2, 4) for b in ("paper", "sa_n")])
        for p in points:
            self.assertEqual(p["params"]["frames"], "3")  # normalised to oprt's text form
            self.assertEqual(p["params"]["resolution"], "8x8")
        self.assertEqual(len({p["dir"] for p in points}), 12)

    def test_zip_groups_vary_together_and_explicit_points_are_added(self):
        spec = self.write_spec({"scenes": [ROOM], "arch": {"level": "lt", "bus": {"model": "shared"}},
                                "grid": {"balance": ["paper", "sa_n"]},
                                "zip": [{"ius": [32, 64], "subdivide": [1, 2]}],
                                "points": [{"ius": 8, "ray_fifo_depth": 4}]})
        _, points = load_spec(spec)
        combos = [(p["params"].get("balance"), p["params"]["ius"], p["params"].get("subdivide")) for p in points]
        self.assertEqual(combos, [("paper", 32, 1), ("paper", 64, 2), ("sa_n", 32, 1), ("sa_n", 64, 2), (None, 8, None)])
        self.assertTrue(all(p["params"]["level"] == "lt" and p["params"]["bus.model"] == "shared" for p in points))
        self.assertEqual(points[-1]["params"]["ray_fifo_depth"], 4)
        self.assertEqual(points[-1]["where"], "/points/0")

    def test_point_directory_depends_only_on_the_point_parameters(self):
        a = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2], "balance": ["sa_n"]}}, "a.json")
        b = self.write_spec({"scenes": [ROOM], "points": [{"balance": "sa_n", "ius": 2}]}, "b.json")
        dirs_a = [p["dir"] for p in load_spec(a)[1]]
        dirs_b = [p["dir"] for p in load_spec(b)[1]]
        self.assertEqual(dirs_b, [dirs_a[1]])
        self.assertTrue(re.fullmatch(r"paper_room-[0-9a-f]{10}", dirs_a[0]))

    def test_architecture_parameters_go_to_the_arch_file_and_run_options_to_flags(self):
        spec = self.write_spec({"scenes": [ROOM], "frames": "0:1",
                                "points": [{"ius": 4, "balance": "sa_n", "ray_fifo_depth": 2, "bus.model": "shared",
                                            "bus.bytes_per_cycle": 4, "costs.triangle": [1, 2, 3, 4]}]})
        point = load_spec(spec)[1][0]
        self.assertEqual(arch_doc(point["params"]),
                         {"format": "oprt-arch/1", "comment": "generated by scripts/sweep", "ray_fifo_depth": 2,
                          "bus": {"model": "shared", "bytes_per_cycle": 4}, "costs": {"triangle": [1, 2, 3, 4]}})
        cmd = command("/bin/oprt", point, "/o/p")
        self.assertEqual(cmd[:8], ["/bin/oprt", "render", ROOM, "--arch", "/o/p/arch.json", "--out", "/o/p",
                                   "--no-progress"])
        self.assertEqual(cmd[8:], ["--frames", "0:1", "--ius", "4", "--balance", "sa_n"])

    def test_iu_parameters_nest_in_the_arch_file_and_the_technology_table_is_a_flag(self):
        tech = os.path.join(REPO, "testbench", "tech", "45nm.json")
        spec = self.write_spec({"scenes": [ROOM], "arch": {"iu": {"model": "pipelined", "fp_latency": {"add": 2}}},
                                "points": [{"tech": os.path.relpath(tech, self.dir), "iu.triangle.adders": 6,
                                            "iu.stack.depth": 4}]})
        point = load_spec(spec)[1][0]
        self.assertEqual(arch_doc(point["params"]),
                         {"format": "oprt-arch/1", "comment": "generated by scripts/sweep",
                          "iu": {"model": "pipelined", "fp_latency": {"add": 2}, "triangle": {"adders": 6},
                                 "stack": {"depth": 4}}})
        cmd = command("/bin/oprt", point, "/o/p")
        self.assertEqual(os.path.normpath(cmd[cmd.index("--tech") + 1]), tech)
        r = self.sweep(self.write_spec({"scenes": [ROOM], "points": [{"tech": "no_such_table.json"}]}))
        self.assertEqual(r.returncode, 2)
        self.assertIn("/points/0/tech: no technology table", r.stderr)
        r = self.sweep(self.write_spec({"scenes": [ROOM], "arch": {"iu": {"model": "vliw"}}, "grid": {"ius": [1]}}))
        self.assertEqual(r.returncode, 2)
        self.assertIn("/arch/iu/model: iu.model: unknown value", r.stderr)

    def test_dry_run_lists_every_point_and_runs_nothing(self):
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2, 3]}})
        r = self.sweep(spec, "--dry-run")
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertEqual(len(lines), 3)
        self.assertTrue(lines[2].startswith("point 2 paper_room-"))
        self.assertIn("--ius 3", lines[2])
        self.assertEqual(self.runs(), [])
        self.assertFalse(os.path.exists(self.out))


class TestBadSpec(SweepTestCase):
    CASES = [
        ({"grid": {"iu": [1]}}, "spec.json: /grid/iu: unknown parameter"),
        ({"grid": {"ius": [True]}}, "spec.json: /grid/ius/0: ius: expected an integer, found true"),
        ({"grid": {"ius": 8}}, "spec.json: /grid/ius: expected a list of values, found 8"),
        ({"grid": {}}, "spec.json: /grid: empty grid"),
        ({"grid": {"ius": []}}, "spec.json: /grid/ius: empty list of values"),
        ({}, 'spec.json: /: nothing to sweep: give "grid", "zip" or "points"'),
        ({"grid": {"balance": ["best"]}}, 'spec.json: /grid/balance/0: balance: unknown value "best"'),
        ({"grid": {"ius": [1]}, "colour": "red"}, "spec.json: /colour: unknown key"),
        ({"scenes": ["nowhere.json"], "grid": {"ius": [1]}}, "spec.json: /scenes/0: no scene file"),
        ({"grid": {"bus.bytes_per_cycle": [1, 2]}}, "spec.json: /grid/bus.bytes_per_cycle: bus.bytes_per_cycle needs bus.model"),
        ({"zip": [{"ius": [1, 2], "subdivide": [1]}]}, "spec.json: /zip/0: lists of unequal length [1, 2]"),
        ({"grid": {"ius": [1]}, "zip": [{"ius": [2]}]}, "spec.json: /zip/0/ius: parameter already varied at /grid/ius"),
        ({"grid": {"ius": [2]}, "points": [{"ius": 2}]}, "spec.json: /points/0: the same point twice (also from /grid)"),
        ({"arch": {"bus": {"modle": "shared"}}, "grid": {"ius": [1]}}, "spec.json: /arch/bus/modle: unknown architecture key"),
        ({"format": "oprt-sweep/2", "grid": {"ius": [1]}}, 'spec.json: /format: expected "oprt-sweep/1"'),
    ]

    def test_every_bad_spec_fails_with_its_place_before_anything_runs(self):
        for spec, message in self.CASES:
            with self.subTest(spec=spec):
                spec_file = self.write_spec({"scenes": [ROOM], **spec})
                r = self.sweep(spec_file)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(message, r.stderr)
                self.assertEqual(r.stderr.count("\n"), 1, "one message")
                self.assertEqual(self.runs(), [], "nothing ran")
                self.assertFalse(os.path.exists(self.out), "nothing written")

    # Numbers are oprt's to judge (`oprt render --check`, base/numbers.h): the real binary.
    NUMBER_CASES = [
        ({"grid": {"ius": [1, 0]}}, "spec.json: /grid/ius/1: ius: value 0 is out of range [1, 65536]"),
        ({"grid": {"ius": ["8", "x"]}}, "spec.json: /grid/ius/1: ius: expected a whole number in [1, 65536]"),
        ({"frames": "60", "grid": {"ius": [1]}}, "spec.json: /frames: frames: scene has frames 0:59 only"),
        ({"points": [{"quantum": "5 parsec"}]}, 'spec.json: /points/0/quantum: quantum: unknown time unit "parsec"'),
        ({"grid": {"memory.sram_bytes": ["1T", "2T"]}},
         "spec.json: /grid/memory.sram_bytes/1: memory.sram_bytes: value 2T (2199023255552 bytes) is more than the "
         "limit: at most 1 TiB"),
        ({"zip": [{"ius": [1, 2], "ray_fifo_depth": [4, 16777217]}]},
         "spec.json: /zip/0/ray_fifo_depth/1: ray_fifo_depth: value 16777217 is out of range [0, 16777216]"),
    ]

    def test_every_bad_number_fails_with_its_place_and_oprts_words_before_anything_runs(self):
        oprt = os.environ.get("OPRT_BINARY")
        if not oprt:
            self.skipTest("OPRT_BINARY is not set")
        for spec, message in self.NUMBER_CASES:
            with self.subTest(spec=spec):
                spec_file = self.write_spec({"scenes": [ROOM], "resolution": "8x8", **spec})
                r = self.sweep(spec_file, oprt=oprt)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(message, r.stderr)
                self.assertEqual(r.stderr.count("\n"), 1, "one message")
                self.assertFalse(os.path.exists(self.out), "nothing written")

    def test_numbers_as_users_write_them_are_taken(self):
        oprt = os.environ.get("OPRT_BINARY")
        if not oprt:
            self.skipTest("OPRT_BINARY is not set")
        spec_file = self.write_spec({"scenes": [ROOM], "resolution": "8x8", "frames": 0,
                                     "points": [{"memory.sram_bytes": "1G", "quantum": "2.5 us", "level": "lt"},
                                                {"memory.sram_bytes": 4294967296}]})
        r = self.sweep(spec_file, oprt=oprt)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual([row["memory.sram_bytes"] for row in self.read_csv("aggregate.csv")],
                         [str(1 << 30), str(1 << 32)])

    def test_outputs_that_cannot_be_written_are_refused_before_anything_runs(self):
        spec_file = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1]}})
        with open(self.out, "w") as f:
            f.write("a file where the output folder goes")
        r = self.sweep(spec_file)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(f"--out: {self.out}: is a file, not a folder", r.stderr)
        os.remove(self.out)
        os.makedirs(os.path.join(self.out, "summary.md"))
        r = self.sweep(spec_file)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("summary.md in it is a folder, not a file", r.stderr)
        self.assertEqual(self.runs(), [], "nothing ran")

    def test_malformed_json_names_line_and_column(self):
        path = os.path.join(self.dir, "broken.json")
        with open(path, "w") as f:
            f.write('{"format": "oprt-sweep/1",\n "grid": {"ius": [1,]}}')
        r = self.sweep(path)
        self.assertEqual(r.returncode, 2)
        self.assertRegex(r.stderr, r"broken\.json: line 2, column \d+: not JSON")

    def test_missing_oprt_binary_fails_before_running(self):
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1]}})
        r = self.sweep(spec, oprt=os.path.join(self.dir, "no_such_oprt"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("no oprt binary at", r.stderr)


class TestResume(SweepTestCase):
    def wait_for(self, condition, what, timeout=30):
        end = time.time() + timeout
        while not condition():
            if time.time() > end:
                self.fail(f"timed out waiting for {what}")
            time.sleep(0.05)

    def test_killed_sweep_resumes_without_redoing_finished_points(self):
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2, 3]}})
        dirs = [p["dir"] for p in load_spec(spec)[1]]
        point_dir = lambda i: os.path.join(self.out, "points", dirs[i])
        sweep_proc = subprocess.Popen([sys.executable, SWEEP, spec, "--out", self.out, "--oprt", self.fake, "--jobs", "1"],
                                      env=dict(self.env, FAKE_OPRT_HANG_IUS="2"),
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # Point 0 finishes; point 1 hangs midway (its partial output written); then a hard kill.
        self.wait_for(lambda: os.path.exists(os.path.join(point_dir(1), "partial.exr")), "point 1 to start")
        self.assertTrue(os.path.exists(os.path.join(point_dir(0), "done.json")))
        with open(os.path.join(point_dir(0), "done.json")) as f:
            done_0 = json.load(f)
        sweep_proc.kill()
        sweep_proc.wait()
        hung_pid = int(read(self.runs_file).split()[-1])
        self.wait_for(lambda: not os.path.exists(f"/proc/{hung_pid}") or
                      read(f"/proc/{hung_pid}/stat").split()[2] == "Z", "the orphaned oprt to end")
        self.assertEqual(self.runs(), dirs[:2])
        self.assertFalse(os.path.exists(os.path.join(point_dir(1), "done.json")))

        r = self.sweep(spec)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("1 of 3 points already done, 2 to run", r.stderr)
        self.assertEqual(self.runs()[:2], dirs[:2])
        self.assertEqual(sorted(self.runs()[2:]), sorted(dirs[1:]), "point 0 not rerun, point 1 rerun, point 2 run")
        with open(os.path.join(point_dir(0), "done.json")) as f:
            self.assertEqual(json.load(f), done_0, "point 0's marker untouched")
        self.assertFalse(os.path.exists(os.path.join(point_dir(1), "partial.exr")), "interrupted point cleaned first")
        self.assertEqual([row["ius"] for row in self.read_csv("aggregate.csv")], ["1", "2", "3"])

        r = self.sweep(spec)  # everything done: nothing runs
        self.assertEqual(r.returncode, 0)
        self.assertEqual(len(self.runs()), 4)

    def test_failed_point_is_recorded_not_aggregated_and_rerun_on_resume(self):
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2, 3]}})
        dirs = [p["dir"] for p in load_spec(spec)[1]]
        r = self.sweep(spec, env=dict(self.env, FAKE_OPRT_FAIL_IUS="3"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("point 2 failed (exit status 2): oprt: fake failure for --ius 3", r.stderr)
        self.assertRegex(r.stdout, r"\n2 .*FAILED \(2\)")
        self.assertEqual([row["status"] for row in self.read_csv("status.csv")], ["done", "done", "failed"])
        self.assertEqual([row["ius"] for row in self.read_csv("aggregate.csv")], ["1", "2"])
        with open(os.path.join(self.out, "points", dirs[2], "failed.json")) as f:
            failure = json.load(f)
        self.assertEqual(failure["exit_status"], 2)
        self.assertEqual(failure["command"][1:3], ["render", ROOM])

        r = self.sweep(spec)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(self.runs()[:3]), sorted(dirs))
        self.assertEqual(self.runs()[3:], [dirs[2]], "only the failed point rerun")
        self.assertFalse(os.path.exists(os.path.join(self.out, "points", dirs[2], "failed.json")))
        self.assertEqual([row["ius"] for row in self.read_csv("aggregate.csv")], ["1", "2", "3"])

    def test_aggregate_only_runs_nothing_and_reports_missing_points(self):
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2]}})
        self.sweep(spec, "--point", "1")
        r = self.sweep(spec, "--aggregate-only")
        self.assertEqual(r.returncode, 1)
        self.assertIn("1 of 2 points done", r.stderr)
        self.assertEqual(len(self.runs()), 1)
        self.assertEqual([row["status"] for row in self.read_csv("status.csv")], ["not run", "done"])


class TestSlurm(SweepTestCase):
    def test_array_script_is_valid_bash_and_runs_each_point_exactly_once(self):
        spec = self.write_spec({"scenes": [ROOM, POLYGONS], "grid": {"ius": [1, 2, 4], "balance": ["paper"]},
                                "points": [{"ius": 8}]})
        all_dirs = [p["dir"] for p in load_spec(spec)[1]]
        script = os.path.join(self.dir, "sweep.sbatch")
        r = self.sweep(spec, "--slurm", script, "--sbatch=--time=00:10:00")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(subprocess.run(["bash", "-n", script]).returncode, 0)
        text = read(script)
        self.assertRegex(text, r"(?m)^#SBATCH --array=0-7$")
        self.assertRegex(text, r"(?m)^#SBATCH --time=00:10:00$")
        self.assertTrue(os.path.isdir(os.path.join(self.out, "slurm")), "Slurm's --output directory exists")

        seen = []
        for task in range(8):
            r = subprocess.run(["bash", script, "--dry-run"], capture_output=True, text=True,
                               env=dict(self.env, SLURM_ARRAY_TASK_ID=str(task)))
            self.assertEqual(r.returncode, 0, r.stderr)
            lines = r.stdout.splitlines()
            self.assertEqual(len(lines), 1, "a task runs exactly one point")
            self.assertTrue(lines[0].startswith(f"point {task} "))
            seen.append(lines[0].split()[2])
        self.assertEqual(seen, all_dirs, "every point exactly once")
        self.assertEqual(self.runs(), [])

        r = subprocess.run(["bash", script], capture_output=True, text=True, env=dict(self.env, SLURM_ARRAY_TASK_ID="8"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("--point 8: the sweep has points 0..7", r.stderr)
        r = subprocess.run(["bash", script], capture_output=True, text=True, env=self.env)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("SLURM_ARRAY_TASK_ID", r.stderr)

        # A real task runs its point only; aggregation afterwards with the same SPEC.
        r = subprocess.run(["bash", script], capture_output=True, text=True, env=dict(self.env, SLURM_ARRAY_TASK_ID="5"))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.runs(), [all_dirs[5]])
        r = self.sweep(spec, "--aggregate-only")
        self.assertIn("1 of 8 points done", r.stderr)

        # The SPEC changed after the script was written: the tasks refuse to run the wrong points.
        self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2]}})
        r = subprocess.run(["bash", script], capture_output=True, text=True, env=dict(self.env, SLURM_ARRAY_TASK_ID="0"))
        self.assertEqual(r.returncode, 2)
        self.assertIn("the SPEC has changed since the Slurm script was written", r.stderr)


def have_matplotlib():
    return subprocess.run([sys.executable, "-c", "import matplotlib"], capture_output=True).returncode == 0


@unittest.skipUnless(have_matplotlib(), "needs matplotlib")
class TestPlots(SweepTestCase):
    def test_one_figure_per_varied_axis_and_scene_and_bars_for_chosen_points(self):
        spec = self.write_spec({"scenes": [ROOM], "arch": {"bus": {"model": "shared"}},
                                "grid": {"ius": [1, 2], "ray_fifo_depth": [0, 4, 16], "bus.bytes_per_cycle": [4, 8]}})
        self.assertEqual(self.sweep(spec).returncode, 0)
        rows = self.read_csv("aggregate.csv")
        self.assertEqual({(r["ray_fifo_depth"], r["bus.bytes_per_cycle"], r["bus.model"]) for r in rows},
                         {(d, b, "shared") for d in ("0", "4", "16") for b in ("4", "8")})
        plots = os.path.join(self.dir, "plots")
        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots,
                            "--bars", "scene=paper_room,ius=2,ray_fifo_depth=4,bus.bytes_per_cycle=8",
                            "--bars", "ius=1,ray_fifo_depth=0,bus.bytes_per_cycle=4"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(os.listdir(plots)), sorted(
            ["bars.png", "scaling_paper_room.png", "effect_ray_fifo_depth_paper_room.png",
             "effect_bus_bytes_per_cycle_paper_room.png"]))

        # --table: a row per IU count, a column per (FIFO depth, bus bandwidth), each cell the
        # point's makespan in million cycles and efficiency, as in aggregate.csv.
        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots, "--table"],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = [l for l in r.stdout.splitlines() if l.startswith("|")]
        header = [c.strip() for c in lines[0].strip("|").split("|")]
        self.assertEqual(header[0], "ius")
        self.assertEqual(len(header), 1 + 6)
        col = header.index("FIFO 4, bus 8 B/cycle")
        row = next(l for l in lines[2:] if l.split("|")[1].strip() == "2")
        cell = row.strip("|").split("|")[col].strip()
        point = next(p for p in rows if p["ius"] == "2" and p["ray_fifo_depth"] == "4" and p["bus.bytes_per_cycle"] == "8")
        self.assertEqual(cell, f"{float(point['makespan_cycles']) / 1e6:.1f} ({float(point['parallel_efficiency']):.2f})")

        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots,
                            "--bars", "ius=3"], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--bars ius=3: no point matches", r.stderr)


@unittest.skipUnless(have_matplotlib(), "needs matplotlib")
class TestPareto(SweepTestCase):
    def test_pareto_points_are_those_no_other_point_beats_and_the_budget_picks_the_fastest_that_fits(self):
        # The fake oprt: area = IUs mm2, frame time = 10 us / IUs, energy growing with the IUs;
        # sa_n twice as slow (and as costly) as paper at the same area: dominated.
        spec = self.write_spec({"scenes": [ROOM], "grid": {"ius": [1, 2, 4], "balance": ["paper", "sa_n"]}})
        self.assertEqual(self.sweep(spec).returncode, 0)
        rows = self.read_csv("aggregate.csv")
        self.assertEqual({(r["ius"], r["balance"], r["area_mm2"]) for r in rows},
                         {(str(n), b, f"{float(n)}") for n in (1, 2, 4) for b in ("paper", "sa_n")})
        plots = os.path.join(self.dir, "plots")
        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots, "--pareto",
                            "--budget", "3", "--table"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(os.listdir(plots), ["pareto_paper_room.png"])
        fronts = r.stdout.split("**")[1::2]
        self.assertEqual(len(fronts), 2)  # frame time against area, energy against frame time
        tables = [block for block in r.stdout.split("\n\n") if block.startswith("| configuration")]
        for table in tables:
            self.assertEqual(len([l for l in table.splitlines() if l.startswith("|")]), 2 + 3,
                             "the three paper points, not sa_n")
            self.assertIn("| serial, 4 IUs, FIFO unbounded | 4.00 | 0.003 |", table)
        self.assertIn("within 3 mm2 the fastest is serial, 2 IUs, FIFO unbounded: 2.00 mm2, 0.005 ms", r.stdout)
        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots, "--pareto",
                            "--budget", "0.5"], capture_output=True, text=True)
        self.assertIn("no configuration fits 0.5 mm2 (the smallest, serial, 1 IUs, FIFO unbounded, takes 1.00 mm2)",
                      r.stdout)


@unittest.skipUnless(os.environ.get("OPRT_BINARY"), "needs OPRT_BINARY (the real oprt)")
class TestRealSweep(SweepTestCase):
    def test_small_real_sweep_aggregates_every_point_and_frame(self):
        spec = self.write_spec({"scenes": [ROOM], "frames": "0:1", "resolution": "16x16", "arch": {"level": "lt"},
                                "grid": {"ius": [1, 4], "balance": ["paper", "sa_n"]}})
        r = self.sweep(spec, "--jobs", "2", oprt=os.environ["OPRT_BINARY"])
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.read_csv("aggregate.csv")
        self.assertEqual([(row["ius"], row["balance"], row["frame"]) for row in rows],
                         [(n, b, f) for n in ("1", "4") for b in ("paper", "sa_n") for f in ("0", "1")])
        for row in rows:
            with open(os.path.join(self.out, row["dir"], "stats.json")) as f:
                stats = json.load(f)
            frame = stats["frames"][int(row["frame"])]
            self.assertEqual(int(row["makespan_cycles"]), frame["makespan_cycles"])
            self.assertEqual(int(row["busy_cycles"]), frame["busy_cycles"])
            self.assertEqual(int(row["units"]), int(row["ius"]))
            self.assertEqual(row["level"], "lt")
            self.assertEqual(row["resolution"], "16x16")
            self.assertEqual(int(row["rays_primary"]), 256)
            busy = [u["busy_cycles"] for u in frame["ius"]]
            self.assertEqual((int(row["unit_busy_min"]), int(row["unit_busy_max"])), (min(busy), max(busy)))
            self.assertLessEqual(int(row["unit_busy_max"]), int(row["makespan_cycles"]))
            self.assertAlmostEqual(float(row["parallel_efficiency"]),
                                   int(row["busy_cycles"]) / (int(row["units"]) * int(row["makespan_cycles"])), places=5)
        one_iu = [row for row in rows if row["ius"] == "1"]
        self.assertTrue(all(float(row["parallel_efficiency"]) == 1.0 for row in one_iu))
        self.assertIn("makespan Mcyc", r.stdout)
        self.assertEqual(len(r.stdout.splitlines()), 1 + 4, "summary: a header and a line per point")
        summary = read(os.path.join(self.out, "summary.md"))
        self.assertEqual(summary.count("\n"), 2 + 4)

        if not have_matplotlib():
            self.skipTest("no matplotlib for the plots")
        plots = os.path.join(self.dir, "plots")
        r = subprocess.run([sys.executable, PLOT, os.path.join(self.out, "aggregate.csv"), "--out", plots,
                            "--bars", "ius=4,balance=sa_n", "--frame", "1"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(os.listdir(plots)), ["bars.png", "scaling_paper_room.png"])
        for name in os.listdir(plots):
            with open(os.path.join(plots, name), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")


if __name__ == "__main__":
    unittest.main()
