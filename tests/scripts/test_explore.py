#!/usr/bin/python3
"""Tests of scripts/explore and scripts/explore_target (run by ctest, one entry per test class).

They drive the real oprt ($OPRT_BINARY) on the room at 8x8 or 16x16 pixels, through a wrapper
that logs every render's output folder (and can slow it down, to be interrupted mid-run).
Figures are checked against each run's own stats.json, fronts and hypervolumes against
computations written here, independently of the script's.
"""
import csv
import json
import os
import shlex
import shutil
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXPLORE = os.path.join(REPO, "scripts", "explore")
TARGET = os.path.join(REPO, "scripts", "explore_target")
ROOM = os.path.join(REPO, "scenes", "paper_room.json")
TECH45 = os.path.join(REPO, "testbench", "tech", "45nm.json")
OPRT = os.environ.get("OPRT_BINARY")
OBJECTIVES = ["frame_time_s", "energy_j", "area_mm2"]

# Logs "<--out folder>" of every render (and every line of a batch) to $RUNS_LOG, sleeps $SLOW
# seconds (not for the one-pixel probes; once per batch), then becomes the real oprt (exec: it keeps the parent-death signal explore sets).
WRAPPER = r'''#!/bin/bash
if [ "$1" = render ]; then
  prev=""; for a in "$@"; do [ "$prev" = "--out" ] && echo "$a" >> "$RUNS_LOG"; prev="$a"; done
  case " $* " in *" --resolution 1x1 "*) ;; *) sleep "${SLOW:-0}";; esac
elif [ "$1" = batch ]; then  # each line's "out", as a render's --out
  prev=""; for a in "$@"; do [ "$prev" = "--archs" ] && archs="$a"; prev="$a"; done
  grep -o '"out": "[^"]*"' "$archs" | sed 's/^"out": "//; s/"$//' >> "$RUNS_LOG"
  sleep "${SLOW:-0}"
fi
exec "$REAL_OPRT" "$@"
'''


def have_optuna():
    return subprocess.run([sys.executable, "-c", "import optuna"], capture_output=True).returncode == 0


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def dominates(a, b):
    return all(x <= y for x, y in zip(a, b)) and any(x < y for x, y in zip(a, b))


def hypervolume(points, ref):
    """Exact hypervolume of points (minimised, each <= ref) by slicing: along the last axis,
    each slab's cross-section is the union of boxes (lower dimension, recursively)."""
    points = [p for p in points if all(x <= r for x, r in zip(p, ref))]
    if not points:
        return 0.0
    if len(ref) == 1:
        return ref[0] - min(p[0] for p in points)
    cuts = sorted({p[-1] for p in points}) + [ref[-1]]
    total = 0.0
    for lo, hi in zip(cuts, cuts[1:]):
        section = [p[:-1] for p in points if p[-1] <= lo]
        total += (hi - lo) * hypervolume(section, ref[:-1])
    return total


@unittest.skipUnless(OPRT and have_optuna(), "needs OPRT_BINARY (the real oprt) and python3-optuna")
class ExploreTestCase(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="oprt_explore_test_")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)
        self.out = os.path.join(self.dir, "out")
        self.wrapper = os.path.join(self.dir, "oprt")
        with open(self.wrapper, "w") as f:
            f.write(WRAPPER)
        os.chmod(self.wrapper, 0o755)
        self.runs_log = os.path.join(self.dir, "runs.txt")
        self.env = dict(os.environ, RUNS_LOG=self.runs_log, REAL_OPRT=OPRT, SLOW="0",
                        SYSTEMC_DISABLE_COPYRIGHT_MESSAGE="1")

    def space(self, parameters, name="space.json", **extra):
        doc = {"format": "oprt-space/1", "scenes": [ROOM], "frames": "0", "resolution": "8x8",
               "parameters": parameters, "objectives": OBJECTIVES, "constraints": {"area_mm2": {"max": 10}},
               "references": {"paper": {"ius": 32, "tech": TECH45}}}
        doc.update(extra)
        doc = {k: v for k, v in doc.items() if v is not None}
        path = os.path.join(self.dir, name)
        with open(path, "w") as f:
            json.dump(doc, f)
        return path

    def explore_cmd(self, space, *args, out=None):
        return [sys.executable, EXPLORE, space, "--out", out or self.out, "--oprt", self.wrapper, *args]

    def explore(self, space, *args, out=None, env=None, timeout=600):
        return subprocess.run(self.explore_cmd(space, *args, out=out), capture_output=True, text=True,
                              env=env or self.env, timeout=timeout)

    def runs(self):
        if not os.path.exists(self.runs_log):
            return []
        with open(self.runs_log) as f:
            return [line.strip() for line in f]

    def rows(self, name="evaluations.csv", out=None):
        return read_csv(os.path.join(out or self.out, name))

    def figures_of_trial(self, trial, out=None):
        """A trial's figures from its own stats.json (one scene, one frame here)."""
        with open(os.path.join(out or self.out, "trials", f"{int(trial):05d}", "paper_room", "stats.json")) as f:
            s = json.load(f)
        fr = s["frames"][0]
        return {"frame_time_s": fr["frame_time_s"], "energy_j": fr["energy_j"]["total"], "area_mm2": s["area_mm2"]["total"]}

    def study_counts(self, out=None):
        """(trials per state, evaluations) read from the SQLite file directly."""
        con = sqlite3.connect(os.path.join(out or self.out, "study.db"))
        try:
            states = dict(con.execute("select state, count(*) from trials group by state").fetchall())
            evaluations = con.execute("select count(*) from trial_user_attributes a join trials t on a.trial_id = t.trial_id "
                                      "where a.key = 'evaluation' and t.state = 'COMPLETE'").fetchone()[0]
        finally:
            con.close()
        return states, evaluations

    def wait_for_evaluations(self, proc, n, limit=120):
        t0 = time.time()
        while time.time() - t0 < limit:
            if proc.poll() is not None:
                self.fail(f"explore ended early: {proc.returncode}")
            path = os.path.join(self.out, "evaluations.csv")
            if os.path.exists(path) and len(self.rows()) >= n:
                return
            time.sleep(0.1)
        self.fail(f"no {n} evaluations within {limit} s")


SMALL = {"ius": {"choice": [2, 8]}, "memory.cache.ways": {"choice": [1, 4]}, "accel": {"choice": ["brute", "bvh"]},
         "memory.sram_bytes": 128, "tech": TECH45}
# 8 points: with 128 bytes of object memory, 4 ways of 64-byte lines do not fit one cache set:
# oprt refuses those 4 (a combination: each value alone is fine), so they are infeasible.


class TestSpaceErrors(ExploreTestCase):
    def check_error(self, space, where, text, *args):
        r = self.explore(space, *args)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn(f"{space}: {where}: ", r.stderr)
        self.assertIn(text, r.stderr)
        self.assertFalse(os.path.exists(self.out), "nothing written")
        self.assertEqual([run for run in self.runs() if "--resolution 1x1" not in run and "oprt-explore-probe" not in run], [],
                         "no evaluation")

    def test_unknown_parameter(self):
        self.check_error(self.space({"ius": {"choice": [2, 4]}, "iu.modle": {"choice": ["serial", "pipelined"]}}),
                         "/parameters/iu.modle", "unknown parameter iu.modle: neither an oprt render option nor an "
                                                 "architecture-file key")
        self.check_error(self.space({"ius": {"choice": [2, 4]}, "units": 3}), "/parameters/units", "unknown parameter units")

    def test_value_oprt_refuses(self):
        self.check_error(self.space({"iu.model": {"choice": ["serial", "pipelind"]}}), "/parameters/iu.model/choice/1",
                         'iu.model = pipelind: oprt refuses it: /iu/model: unknown value "pipelind"')
        self.check_error(self.space({"ius": {"int": [0, 4]}}), "/parameters/ius/int", "ius = 0: oprt refuses it")
        self.check_error(self.space({"ius": {"choice": [2, 4]}, "tech": os.path.join(self.dir, "none.json")}),
                         "/parameters/tech", "tech: no file")

    def test_empty_ranges(self):
        self.check_error(self.space({"ius": {"int": [8, 4]}}), "/parameters/ius/int", "empty range [8, 4]: lo is above hi")
        self.check_error(self.space({"ius": {"choice": []}}), "/parameters/ius/choice", "empty choice")
        self.check_error(self.space({"clock_mhz": {"float": [200.0, 100.0]}}), "/parameters/clock_mhz/float",
                         "empty range [200.0, 100.0]")
        self.check_error(self.space({"ius": {"int": [0, 4], "log": True}}), "/parameters/ius/int", "a log range needs lo > 0")
        self.check_error(self.space({"ius": {"int": [2, 4], "step": 2}}), "/parameters/ius/step", "unknown key")

    def test_bad_constraints(self):
        p = {"ius": {"choice": [2, 4]}}
        self.check_error(self.space(p, constraints={"area_mm2": 10}), "/constraints/area_mm2", 'expected {"max": number}')
        self.check_error(self.space(p, constraints={"area_mm2": {"below": 10}}), "/constraints/area_mm2/below",
                         'unknown bound (expected "max" or "min")')
        self.check_error(self.space(p, constraints={"area_mm2": {"max": "ten"}}), "/constraints/area_mm2/max",
                         'expected a number, found "ten"')
        self.check_error(self.space(p, constraints={"area_mm2": {"max": 5, "min": 8}}), "/constraints/area_mm2",
                         "min 8 is above max 5")
        self.check_error(self.space(p, constraints={"frame_rate": {"max": 60}}), "/constraints/frame_rate",
                         "unknown key frame_rate: neither an objective")
        # A per-frame figure of stats.json (nested: dotted) is a valid bound: the space passes its
        # checks (--slurm runs nothing after them).
        ok = self.space(p, constraints={"parallel_efficiency": {"min": 0.1}, "energy_j.total": {"max": 1}})
        r = self.explore(ok, "--slurm")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_other_space_errors(self):
        p = {"ius": {"choice": [2, 4]}}
        self.check_error(self.space(p, objectives=["frame_time_s"]), "/objectives", "expected two or three")
        self.check_error(self.space(p, objectives=["frame_time_s", "speed"]), "/objectives/1", 'unknown objective "speed"')
        self.check_error(self.space({"ius": {"choice": [2, 4]}, "level": "at"}), "/parameters/level",
                         "not a parameter: evaluations run --level analytic")
        self.check_error(self.space({"ius": 4}), "/parameters", "nothing to search: every parameter is fixed")
        self.check_error(self.space({"ius": {"int": [2, 4]}}), "/parameters/ius", "--grid needs every parameter to be a choice",
                         "--grid")
        self.check_error(self.space(p, frames="70"), "/frames", "has frames 0:59 only")
        self.check_error(self.space(p, bogus=1), "/bogus", "unknown key")

    def test_a_combination_oprt_refuses_is_not_a_space_error(self):
        r = self.explore(self.space(SMALL), "--slurm")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_output_folder_is_checked_before_anything_runs(self):
        space = self.space({"ius": {"choice": [2, 4]}})
        regular = os.path.join(self.dir, "file")
        open(regular, "w").close()
        fifo = os.path.join(self.dir, "fifo")
        os.mkfifo(fifo)
        foreign = os.path.join(self.dir, "foreign")
        os.makedirs(foreign)
        open(os.path.join(foreign, "thesis.tex"), "w").close()
        for out, text in ((regular, "is a regular file, not a directory"), (fifo, "is a FIFO, not a directory"),
                          ("/dev/null", "is a device, not a directory"),
                          (os.path.join(regular, "sub"), f"cannot be created: {regular} is not a directory"),
                          ("/proc/oprt-explore-out", "cannot be created: /proc is not writable"),
                          (foreign, "a directory that holds other files and no explore.json: not an explore output")):
            r = self.explore(space, out=out)
            self.assertEqual(r.returncode, 2, (out, r.stderr))
            self.assertIn(f"explore: --out {out}: {text}", r.stderr)
        self.assertEqual(os.listdir(foreign), ["thesis.tex"])
        self.assertEqual(self.runs(), [], "the folder is checked before oprt runs at all")


class TestGrid(ExploreTestCase):
    def test_every_point_once_with_figures_from_oprt_and_the_front(self):
        space = self.space(SMALL)
        r = self.explore(space, "--grid", "--jobs", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows()
        params = ["ius", "memory.cache.ways", "accel", "memory.sram_bytes", "tech"]
        with open(os.path.join(self.out, "evaluations.csv")) as f:
            header = f.readline().strip().split(",")
        self.assertEqual(header, ["trial", "state", "reason"] + params + OBJECTIVES + ["wall_s"])
        points = sorted((int(r["ius"]), int(r["memory.cache.ways"]), r["accel"]) for r in rows)
        self.assertEqual(points, sorted((n, w, a) for n in (2, 8) for w in (1, 4) for a in ("brute", "bvh")))
        self.assertEqual(len({r["trial"] for r in rows}), 8)
        progress = [l for l in r.stdout.splitlines() if l.startswith("explore: [")]
        self.assertEqual(len(progress), 8)
        self.assertTrue(progress[-1].startswith("explore: [8/8] trial "))
        for row in rows:
            if row["memory.cache.ways"] == "4":  # 4 x 64 bytes > 128: refused by oprt, with its words
                self.assertEqual(row["state"], "infeasible")
                self.assertIn("refused by oprt: ", row["reason"])
                self.assertIn("smaller than one cache set", row["reason"])
                self.assertEqual([row[o] for o in OBJECTIVES], ["", "", ""])
                continue
            f = self.figures_of_trial(row["trial"])
            for o in OBJECTIVES:
                self.assertEqual(float(row[o]), f[o])
            if f["area_mm2"] > 10:
                self.assertEqual(row["state"], "infeasible")
                self.assertEqual(row["reason"], f"area_mm2 {f['area_mm2']:.6g} > 10 (max)")
            else:
                self.assertEqual((row["state"], row["reason"]), ("complete", ""))
        self.assertTrue(any(r["state"] == "complete" for r in rows))

        # The front: the feasible rows no other feasible row dominates.
        feasible = [r for r in rows if r["state"] == "complete"]
        vec = lambda r: [float(r[o]) for o in OBJECTIVES]
        front = [r for r in feasible if not any(dominates(vec(q), vec(r)) for q in feasible)]
        pareto = self.rows("pareto.csv")
        self.assertEqual(sorted(r["trial"] for r in pareto), sorted(r["trial"] for r in front))
        self.assertEqual(list(pareto[0].keys()), header)
        # Each Pareto point's architecture file is complete: oprt renders it as it is, with the
        # non-architecture options only (--tech), to the same figures.
        for row in pareto:
            arch = os.path.join(self.out, "pareto", f"trial_{int(row['trial']):05d}.json")
            again = os.path.join(self.dir, "again")
            rr = subprocess.run([OPRT, "render", ROOM, "--arch", arch, "--tech", TECH45, "--level", "analytic",
                                 "--frames", "0", "--resolution", "8x8", "--out", again, "--no-progress"],
                                capture_output=True, text=True, env=self.env)
            self.assertEqual(rr.returncode, 0, rr.stderr)
            with open(os.path.join(again, "stats.json")) as f:
                s = json.load(f)
            self.assertEqual(s["frames"][0]["frame_time_s"], float(row["frame_time_s"]))
            self.assertEqual(s["area_mm2"]["total"], float(row["area_mm2"]))
        # Confirmed at --level at (from the Pareto file): within 1 % here (caches in front of DRAM:
        # the analytic level's memory timing is close, not exact).
        confirm = self.rows("confirm.csv")
        self.assertEqual(sorted(c["trial"] for c in confirm), sorted(r["trial"] for r in pareto))
        analytic = {r["trial"]: float(r["frame_time_s"]) for r in pareto}
        for c in confirm:
            self.assertEqual(c["state"], "confirmed")
            with open(os.path.join(self.out, "confirm", f"trial_{int(c['trial']):05d}", "paper_room", "stats.json")) as f:
                at = json.load(f)
            self.assertEqual(at["arch"]["level"], "at")
            self.assertEqual(at["arch"]["source"], os.path.join(self.out, "pareto", f"trial_{int(c['trial']):05d}.json"))
            at_time = at["frames"][0]["frame_time_s"]
            self.assertAlmostEqual(float(c["frame_time_s_error_pct"]), abs(analytic[c["trial"]] - at_time) / at_time * 100,
                                   places=9)
            self.assertLess(float(c["frame_time_s_error_pct"]), 1.0)
        # The hypervolume: each objective over the reference point (here the area bound and the
        # paper's engine, 32 serial IUs, for time and energy).
        with open(os.path.join(self.out, "references", "paper", "result.json")) as f:
            paper = json.load(f)["figures"]
        ref = {"frame_time_s": paper["frame_time_s"], "energy_j": paper["energy_j"], "area_mm2": 10.0}
        with open(os.path.join(self.out, "result.json")) as f:
            result = json.load(f)
        self.assertEqual(result["reference_point"], ref)
        expected = hypervolume([[float(r[o]) / ref[o] for o in OBJECTIVES] for r in feasible], [1.0, 1.0, 1.0])
        self.assertAlmostEqual(result["hypervolume"], expected, places=12)
        curve = self.rows("hypervolume.csv")
        self.assertEqual(len(curve), 8)
        self.assertAlmostEqual(float(curve[-1]["hypervolume"]), expected, places=12)
        self.assertTrue(all(float(a["hypervolume"]) <= float(b["hypervolume"]) for a, b in zip(curve, curve[1:])))
        for png in ("front.png", "hypervolume.png"):
            with open(os.path.join(self.out, png), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with open(os.path.join(self.out, "summary.md")) as f:
            summary = f.read()
        self.assertIn(f"**{len(front)} configurations are Pareto-optimal**", summary)
        self.assertIn("4 refused by oprt", summary)

        # Every point was rendered once (the probes aside), and a rerun evaluates nothing.
        evaluated = [d for d in self.runs() if os.sep + "trials" + os.sep in d]
        self.assertEqual(len(evaluated), 8)
        self.assertEqual(len(set(evaluated)), 8)
        r = self.explore(space, "--grid")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len([d for d in self.runs() if os.sep + "trials" + os.sep in d]), 8)
        r = self.explore(space, "--grid", "--evaluations", "3")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--grid evaluates every one of the space's 8 points", r.stderr)

    def test_killed_grid_resumes_and_evaluates_each_point_exactly_once(self):
        space = self.space(SMALL)
        env = dict(self.env, SLOW="0.6")
        p = subprocess.Popen(self.explore_cmd(space, "--grid", "--jobs", "2", "--no-confirm"), env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.wait_for_evaluations(p, 3)
        p.kill()
        p.wait()
        r = self.explore(space, "--grid", "--jobs", "2", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows()
        self.assertEqual(sorted((r["ius"], r["memory.cache.ways"], r["accel"]) for r in rows),
                         sorted((n, w, a) for n in ("2", "8") for w in ("1", "4") for a in ("brute", "bvh")))


class TestFrames(ExploreTestCase):
    def test_constraints_on_per_frame_figures_take_the_worst_frame(self):
        # Two frames of the moving room, whose per-frame figures differ: a "max" bound is judged
        # on the largest frame's value, a "min" bound on the smallest's; the objectives are the
        # frames' means. Both bounds are out of reach, so each row's reason shows the values used.
        space = self.space({"ius": {"choice": [2, 8]}, "tech": TECH45}, frames="0:1",
                           constraints={"energy_j.total": {"max": 1e-30}, "parallel_efficiency": {"min": 0.999}})
        r = self.explore(space, "--grid")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 2)
        for row in rows:
            with open(os.path.join(self.out, "trials", f"{int(row['trial']):05d}", "paper_room", "stats.json")) as f:
                s = json.load(f)
            frames = s["frames"]
            self.assertEqual([fr["frame"] for fr in frames], [0, 1])
            energy = [fr["energy_j"]["total"] for fr in frames]
            efficiency = [fr["parallel_efficiency"] for fr in frames]
            self.assertNotEqual(max(energy), min(energy), "the frames must differ for this test to mean anything")
            self.assertNotEqual(max(efficiency), min(efficiency))
            self.assertEqual(row["state"], "infeasible")
            self.assertEqual(row["reason"], f"energy_j.total {max(energy):.6g} > 1e-30 (max); "
                                            f"parallel_efficiency {min(efficiency):.6g} < 0.999 (min)")
            times = [fr["frame_time_s"] for fr in frames]
            self.assertAlmostEqual(float(row["frame_time_s"]), (times[0] + times[1]) / 2, delta=1e-12 * max(times))
            self.assertAlmostEqual(float(row["energy_j"]), (energy[0] + energy[1]) / 2, delta=1e-12 * max(energy))

        # Bounds between the two frames' values: the configuration breaks a "max" bound that only
        # its larger frame exceeds, and a "min" bound that only its smaller frame falls below.
        row = rows[0]
        with open(os.path.join(self.out, "trials", f"{int(row['trial']):05d}", "paper_room", "stats.json")) as f:
            frames = json.load(f)["frames"]
        energy = sorted(fr["energy_j"]["total"] for fr in frames)
        efficiency = sorted(fr["parallel_efficiency"] for fr in frames)
        mid_e, mid_p = (energy[0] + energy[1]) / 2, (efficiency[0] + efficiency[1]) / 2
        between = self.space({"ius": {"choice": [2, 8]}, "tech": TECH45}, name="between.json", frames="0:1",
                             constraints={"energy_j.total": {"max": mid_e}, "parallel_efficiency": {"min": mid_p}})
        out = os.path.join(self.dir, "between")
        r = self.explore(between, "--grid", out=out)
        self.assertEqual(r.returncode, 0, r.stderr)
        (again,) = [a for a in self.rows(out=out) if a["ius"] == row["ius"]]
        self.assertEqual(again["state"], "infeasible")
        self.assertEqual(again["reason"], f"energy_j.total {energy[1]:.6g} > {mid_e:g} (max); "
                                          f"parallel_efficiency {efficiency[0]:.6g} < {mid_p:g} (min)")

    def test_an_infeasible_evaluation_keeps_the_hypervolume_reached(self):
        # Two configurations in grid order (2 units, then 8), an area bound between their areas
        # that the first meets and the second does not. The hypervolume curve after the second
        # evaluation is the one after the first (an infeasible point adds nothing and takes
        # nothing away), and it is the box between the point and a reference point far away.
        probe = self.space({"ius": {"choice": [2, 8]}, "tech": TECH45}, name="probe.json", constraints={})
        out = os.path.join(self.dir, "probe")
        r = self.explore(probe, "--grid", out=out)
        self.assertEqual(r.returncode, 0, r.stderr)
        area = {}
        for row in self.rows(out=out):
            with open(os.path.join(out, "trials", f"{int(row['trial']):05d}", "paper_room", "stats.json")) as f:
                area[int(row["ius"])] = json.load(f)["area_mm2"]["total"]
        self.assertNotEqual(area[2], area[8])
        # (Two units hold half the scene each: their memories may well make them the larger.)
        kind = "max" if area[2] < area[8] else "min"
        ref = {"frame_time_s": 1.0, "energy_j": 1.0, "area_mm2": 1000.0}
        space = self.space({"ius": {"choice": [2, 8]}, "tech": TECH45},
                           constraints={"area_mm2": {kind: (area[2] + area[8]) / 2}}, reference_point=ref)
        r = self.explore(space, "--grid")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = sorted(self.rows(), key=lambda row: int(row["trial"]))
        self.assertEqual([(row["ius"], row["state"]) for row in rows], [("2", "complete"), ("8", "infeasible")])
        point = [float(rows[0][o]) / ref[o] for o in OBJECTIVES]
        expected = hypervolume([point], [1.0, 1.0, 1.0])
        self.assertGreater(expected, 0)
        curve = self.rows("hypervolume.csv")
        self.assertEqual(len(curve), 2)
        self.assertAlmostEqual(float(curve[0]["hypervolume"]), expected, places=12)
        self.assertAlmostEqual(float(curve[1]["hypervolume"]), expected, places=12)
        with open(os.path.join(self.out, "result.json")) as f:
            self.assertAlmostEqual(json.load(f)["hypervolume"], expected, places=12)


class TestSearch(ExploreTestCase):
    PARAMS = {"ius": {"int": [1, 16], "log": True}, "iu.model": {"choice": ["serial", "pipelined"]},
              "ray_fifo_depth": {"choice": [0, 64]}, "balance": {"choice": ["paper", "sa_n"]}, "tech": TECH45}

    def test_a_seed_makes_a_search_reproducible_and_a_rerun_extends_it(self):
        space = self.space(self.PARAMS)
        r = self.explore(space, "--evaluations", "6", "--seed", "3", "--jobs", "1", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        other = os.path.join(self.dir, "other")
        r2 = self.explore(space, "--evaluations", "6", "--seed", "3", "--jobs", "1", "--no-confirm", out=other)
        self.assertEqual(r2.returncode, 0, r2.stderr)
        names = ["ius", "iu.model", "ray_fifo_depth", "balance"]
        first = [[row[k] for k in names + OBJECTIVES] for row in self.rows()]
        self.assertEqual(first, [[row[k] for k in names + OBJECTIVES] for row in self.rows(out=other)])
        self.assertEqual(len({tuple(c[:4]) for c in first}), 6, "no configuration evaluated twice")

        r = self.explore(space, "--evaluations", "8", "--seed", "3", "--jobs", "2", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 8)
        self.assertEqual([[row[k] for k in names + OBJECTIVES] for row in rows][:6], first)
        self.assertEqual(len({tuple(row[k] for k in names) for row in rows}), 8)
        mine = [d for d in self.runs() if d.startswith(self.out + os.sep + "trials")]
        self.assertEqual(len(mine), 8, "the first six were not run again")

        r = self.explore(space, "--evaluations", "8", "--seed", "4")
        self.assertEqual(r.returncode, 2)
        self.assertIn("holds a search of seed 3, not this one", r.stderr)

    def test_tpe_sampler(self):
        r = self.explore(self.space(self.PARAMS), "--evaluations", "4", "--sampler", "tpe", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(self.rows()), 4)

    def test_a_confirmation_beyond_one_percent_fails_loudly(self):
        # 16x16, FIFOs of 4 rays, a shared bus, pipelined units visited in order of distance:
        # the analytic level's recurrence is 1.4 % off the timing reference on this tiny frame
        # (-0.5 % at 128x128; docs/timing-levels.md).
        space = self.space({"ius": {"choice": [4]}, "iu.model": "pipelined", "ray_fifo_depth": 4, "route": "ordered",
                            "balance": "spatial", "bus.model": "shared", "bus.bytes_per_cycle": 8,
                            "bus.arbitration_cycles": 1, "memory.model": "latency", "memory.latency_cycles": 10,
                            "memory.bytes_per_cycle": 16, "tech": TECH45}, resolution="16x16")
        r = self.explore(space, "--grid")
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("explore: CONFIRMATION FAILED", r.stderr)
        confirm = self.rows("confirm.csv")
        self.assertEqual(len(confirm), 1)
        self.assertGreater(float(confirm[0]["frame_time_s_error_pct"]), 1.0)
        with open(os.path.join(self.out, "confirm", f"trial_{int(confirm[0]['trial']):05d}", "paper_room",
                               "stats.json")) as f:
            at = json.load(f)
        self.assertEqual(at["arch"]["level"], "at")
        self.assertEqual(float(confirm[0]["frame_time_s_at"]), at["frames"][0]["frame_time_s"])
        with open(os.path.join(self.out, "summary.md")) as f:
            self.assertIn("**CONFIRMATION FAILED", f.read())


class TestInterruptions(ExploreTestCase):
    PARAMS = {"ius": {"int": [1, 32], "log": True}, "iu.model": {"choice": ["serial", "pipelined"]},
              "ray_fifo_depth": {"choice": [0, 16, 256]}, "balance": {"choice": ["paper", "sa_n"]}, "tech": TECH45}

    def test_kill_9_mid_run_then_rerun_gives_exactly_n_evaluations(self):
        space = self.space(self.PARAMS)
        env = dict(self.env, SLOW="0.5")
        # Groups of 2 configurations per oprt process (oprt batch): up to 4 evaluations in flight.
        p = subprocess.Popen(self.explore_cmd(space, "--evaluations", "10", "--jobs", "2", "--group", "2", "--no-confirm"), env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.wait_for_evaluations(p, 3)
        p.send_signal(signal.SIGKILL)
        p.wait()
        states, done = self.study_counts()  # the study is readable
        self.assertGreaterEqual(done, 3)
        self.assertGreaterEqual(states.get("RUNNING", 0), 1, "killed with evaluations in flight")
        before = {r["trial"]: r for r in self.rows()}
        # explore's oprt children get SIGKILL from the kernel as explore ends (parent-death
        # signal, docs/explore.md): none is left running. Polled, with a deadline generous
        # enough for a loaded machine; the condition, not the wait, is what is asserted.
        alive = self.children_left(deadline_s=30)
        self.assertEqual(alive, [], "oprt children still running 30 s after explore was killed with -9")

        r = self.explore(space, "--evaluations", "10", "--jobs", "2", "--group", "2", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("was interrupted: its configuration is queued again", r.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 10)
        self.assertEqual(len({r["trial"] for r in rows}), 10)
        names = list(self.PARAMS)
        self.assertEqual(len({tuple(r[k] for k in names) for r in rows}), 10, "no configuration evaluated twice")
        after = {r["trial"]: r for r in rows}
        for trial, row in before.items():
            self.assertEqual(after[trial], row, "finished evaluations are kept as they were")
        runs = [d for d in self.runs() if d.startswith(self.out + os.sep + "trials")]
        finished = {os.path.join(self.out, "trials", f"{int(t):05d}", "paper_room") for t in after}
        self.assertEqual(sorted(d for d in runs if d in finished), sorted(finished), "each evaluation ran once")
        self.assertLessEqual(len(runs) - len(finished), 4, "only the evaluations in flight were lost")
        _, done = self.study_counts()
        self.assertEqual(done, 10)

    def children_left(self, deadline_s):
        """The pids of processes still running for this test's trials (oprt, or the wrapper
        before its exec), polled until there are none or `deadline_s` has passed."""
        end = time.monotonic() + deadline_s
        while True:
            alive = subprocess.run(["pgrep", "-f", self.out + "/trials"], capture_output=True, text=True).stdout.split()
            if not alive or time.monotonic() > end:
                return alive
            time.sleep(0.1)

    def test_sigint_and_sigterm_stop_cleanly_and_resume(self):
        space = self.space(self.PARAMS)
        env = dict(self.env, SLOW="0.5")
        for sig, status in ((signal.SIGTERM, 143), (signal.SIGINT, 130)):
            # One configuration per oprt process: the evaluations in flight are the two running.
            p = subprocess.Popen(self.explore_cmd(space, "--evaluations", "8", "--jobs", "2", "--group", "1",
                                                  "--no-confirm"), env=env,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            self.wait_for_evaluations(p, 2 if sig == signal.SIGTERM else 4)
            p.send_signal(sig)
            _, err = p.communicate(timeout=60)
            self.assertEqual(p.returncode, status, err)
            self.assertIn("run the same command to resume", err)
            states, done = self.study_counts()
            self.assertEqual(states.get("RUNNING", 0), 0, "the trials in flight are closed, not left running")
            self.assertEqual(len(self.rows()), done)
        r = self.explore(space, "--evaluations", "8", "--jobs", "2", "--group", "1", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(self.rows()), 8)
        self.assertEqual(len({tuple(r[k] for k in self.PARAMS) for r in self.rows()}), 8)


class TestSlurm(ExploreTestCase):
    def test_array_tasks_share_one_study(self):
        space = self.space(TestSearch.PARAMS)
        r = self.explore(space, "--slurm", "--jobs", "2", "--evaluations", "6", "--sbatch=--time=00:10:00")
        self.assertEqual(r.returncode, 0, r.stderr)
        script = os.path.join(self.out, "explore.sbatch")
        self.assertEqual(subprocess.run(["bash", "-n", script]).returncode, 0)
        with open(script) as f:
            text = f.read()
        self.assertRegex(text, r"(?m)^#SBATCH --array=0-1$")
        self.assertRegex(text, r"(?m)^#SBATCH --time=00:10:00$")
        self.assertIn(os.path.join(self.out, "study.journal"), text)
        self.assertEqual(subprocess.run(["bash", script], capture_output=True, env=self.env).returncode != 0, True,
                         "refuses to run outside an array task")
        # Two tasks at once, as Slurm would start them.
        tasks = [subprocess.Popen(["bash", script], env=dict(self.env, SLURM_ARRAY_TASK_ID=str(i)),
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for i in (0, 1)]
        for t in tasks:
            out, err = t.communicate(timeout=300)
            self.assertEqual(t.returncode, 0, err)
        # Then the report (the command the script's header names): nothing left to evaluate.
        final = shlex.split(next(l for l in text.splitlines() if "--dependency" in l).split("--wrap ", 1)[1])[0]
        r = subprocess.run(["bash", "-c", final], capture_output=True, text=True, env=self.env, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNotIn("evaluating the rest", r.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 6)
        self.assertEqual(len({tuple(r[k] for k in TestSearch.PARAMS) for r in rows}), 6)
        self.assertTrue(os.path.exists(os.path.join(self.out, "summary.md")))


class TestBudgetAndFidelities(ExploreTestCase):
    PARAMS = {"ius": {"choice": [2, 4, 8, 16]}, "iu.model": {"choice": ["serial", "pipelined"]},
              "ray_fifo_depth": {"choice": [16, 256]}, "balance": {"choice": ["paper", "sa_n"]}, "tech": TECH45}

    def trial_states(self, out=None):
        states, _ = self.study_counts(out)
        return states

    def test_a_budget_ends_the_search_with_no_trial_left_running(self):
        space = self.space(self.PARAMS, resolution="16x16")
        r = self.explore(space, "--budget", "10s", "--jobs", "2", "--no-confirm", "--group", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(self.trial_states().get("RUNNING", 0), 0)
        with open(os.path.join(self.out, "result.json")) as f:
            res = json.load(f)
        self.assertEqual(res["budget_s"], 10)
        self.assertIn("search", res["phases_s"])
        self.assertEqual(len(self.rows()), res["evaluations"])  # however many a loaded machine allowed
        self.assertNotIn("screen", res["fidelities"])  # 16x16: no screening
        with open(os.path.join(self.out, "summary.md")) as f:
            self.assertIn("## How the time went", f.read())

    def test_screening_promotes_to_the_target_fidelity_and_measures_its_error(self):
        space = self.space(self.PARAMS, resolution="64x64")
        r = self.explore(space, "--evaluations", "36", "--jobs", "2", "--no-confirm")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = self.rows()
        self.assertEqual(len(rows), 36)
        sizes = {}
        for row in rows:  # each evaluation's own stats.json: 16x16 screened, 64x64 promoted
            with open(os.path.join(self.out, "trials", f"{int(row['trial']):05d}", "paper_room", "stats.json")) as f:
                sizes[row["trial"]] = tuple(json.load(f)["resolution"])
        self.assertEqual(set(sizes.values()), {(16, 16), (64, 64)})
        for row in self.rows("pareto.csv"):  # the front: the target fidelity only
            self.assertEqual(sizes[row["trial"]], (64, 64))
        fid = {row["objective"]: row for row in self.rows("fidelity.csv")}
        self.assertEqual(set(fid), set(OBJECTIVES))
        self.assertAlmostEqual(float(fid["area_mm2"]["spearman"]), 1.0, places=12)  # area does not depend on the resolution
        self.assertEqual(float(fid["area_mm2"]["max_rel_error_pct"]), 0.0)
        self.assertEqual(float(fid["frame_time_s"]["scale"]), 16.0)  # (64 * 64) / (16 * 16) pixels

    def test_reuse_seeds_the_study_with_an_earlier_search(self):
        space = self.space(self.PARAMS, resolution="8x8")
        first = os.path.join(self.dir, "first")
        r = self.explore(space, "--evaluations", "6", "--no-confirm", out=first)
        self.assertEqual(r.returncode, 0, r.stderr)
        before = len(self.runs())
        r = self.explore(space, "--evaluations", "9", "--no-confirm", "--reuse", first)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"--reuse {first}: 6 evaluated configurations of this space added to the study", r.stderr)
        mine, theirs = self.rows(), {json.dumps({k: v for k, v in row.items() if k not in ("trial", "wall_s")})
                                     for row in self.rows(out=first)}
        self.assertEqual(len(mine), 9)
        seeded = [row for row in mine if json.dumps({k: v for k, v in row.items() if k not in ("trial", "wall_s")}) in theirs]
        self.assertEqual(len(seeded), 6, "the earlier evaluations, figures and all")
        new_runs = [d for d in self.runs()[before:] if d.startswith(self.out + os.sep + "trials")]
        self.assertEqual(len(new_runs), 3, "only the 3 new configurations rendered")


class TestTarget(ExploreTestCase):
    def test_searches_take_the_grids_figures_and_report_their_share_of_its_hypervolume(self):
        space = self.space({"ius": {"choice": [1, 2, 4, 8]}, "iu.model": {"choice": ["serial", "pipelined"]},
                            "balance": {"choice": ["paper", "sa_n"]}, "tech": TECH45},
                           reference_point={"frame_time_s": 0.1, "energy_j": 0.01, "area_mm2": 10})
        target = os.path.join(self.dir, "target")
        r = subprocess.run([sys.executable, TARGET, space, "--out", target, "--fraction", "0.5", "--seeds", "0,1",
                            "--oprt", self.wrapper], capture_output=True, text=True, env=self.env, timeout=600)
        self.assertIn(r.returncode, (0, 1), r.stderr)
        grid = {tuple(row[k] for k in ("ius", "iu.model", "balance")): row for row in self.rows(out=os.path.join(target, "grid"))}
        self.assertEqual(len(grid), 16)
        with open(os.path.join(target, "grid", "result.json")) as f:
            ghv = json.load(f)["hypervolume"]
        self.assertGreater(ghv, 0)
        with open(os.path.join(target, "target.md")) as f:
            table = f.read()
        ratios = []
        for seed in (0, 1):
            folder = os.path.join(target, f"nsga2-seed{seed}")
            rows = self.rows(out=folder)
            self.assertEqual(len(rows), 8)
            for row in rows:  # the grid's figures, not a new run
                g = grid[tuple(row[k] for k in ("ius", "iu.model", "balance"))]
                self.assertEqual([row[k] for k in ["state", "reason"] + OBJECTIVES], [g[k] for k in ["state", "reason"] + OBJECTIVES])
            self.assertFalse(os.path.exists(os.path.join(folder, "trials")), "nothing rendered")
            with open(os.path.join(folder, "result.json")) as f:
                res = json.load(f)
            ratios.append(res["hypervolume"] / ghv)
            self.assertIn(f"| seed {seed} | 8 | {res['hypervolume']:.5f} | {ratios[-1] * 100:.1f} % |", table)
            self.assertLessEqual(ratios[-1], 1.0 + 1e-12)
        median = sum(ratios) / 2
        self.assertIn(f"Median over 2 seeds: **{median * 100:.1f} %**", table)
        self.assertEqual(r.returncode, 0 if median >= 0.95 else 1)


if __name__ == "__main__":
    unittest.main()
