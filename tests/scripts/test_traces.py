#!/usr/bin/python3
"""The traces of `oprt render` read by the real readers: the FST through GTKWave's fst2vcd
(and our VCD through vcd2fst and back), the timeline through Python's json module; their
values checked against stats.json, and the --trace-* selections against the full trace.
Runs $OPRT_BINARY on small room frames."""
import json
import os
import shutil
import subprocess
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ROOM = os.path.join(REPO, "scenes", "paper_room.json")
PAPER = os.path.join(REPO, "testbench", "arch", "paper.json")
# Every source of stall and wait at once: a shared bus, shallow FIFOs, memory latency, GPP costs.
CONTENDED = {"format": "oprt-arch/1", "ius": 8, "ray_fifo_depth": 2,
             "bus": {"model": "shared", "bytes_per_cycle": 8, "arbitration_cycles": 1},
             "memory": {"model": "latency", "latency_cycles": 10, "bytes_per_cycle": 16},
             "gpp": {"cycles_per_ray": 4, "cycles_per_hit": 30}}
PHASES = ("sphere", "transform", "primitive", "stall", "box")  # state codes 1..5


def gtkwave_tool(name):
    path = shutil.which(name)
    if not path:
        raise AssertionError(f"{name} not found: scripts/setup installs Debian's gtkwave")
    return path


def parse_vcd(path):
    """{signal: [(time, value)]}: each signal's value changes, the last of a time kept."""
    names, scope, out, t, defs = {}, [], {}, None, True
    with open(path) as f:
        for line in f:
            s = line.split()
            if not s:
                continue
            if defs:
                if s[0] == "$scope":
                    scope.append(s[2])
                elif s[0] == "$upscope":
                    scope.pop()
                elif s[0] == "$var":
                    names.setdefault(s[3], []).append(".".join(scope + [s[4]]))
                elif s[0] == "$enddefinitions":
                    defs = False
                continue
            if s[0][0] == "#":
                t = int(s[0][1:])
                continue
            if s[0][0] == "$":
                continue
            value, code = (s[0][1:], s[1]) if s[0][0] == "b" else (s[0][0], s[0][1:])
            value = int(value, 2)
            for n in names[code]:
                changes = out.setdefault(n, [])
                if changes and changes[-1][0] == t:
                    changes[-1] = (t, value)
                else:
                    changes.append((t, value))
    for n, changes in out.items():  # a value written again unchanged is no change
        kept = []
        for tv in changes:
            if not kept or kept[-1][1] != tv[1]:
                kept.append(tv)
        out[n] = kept
    out["#end"] = t
    return out


def value_at(changes, t):
    v = None
    for time, value in changes:
        if time > t:
            break
        v = value
    return v


def time_in(changes, value, start, end):
    """How long the signal holds `value` within [start, end)."""
    total = 0
    for i, (t, v) in enumerate(changes):
        t1 = changes[i + 1][0] if i + 1 < len(changes) else end
        lo, hi = max(t, start), min(t1, end)
        if v == value and hi > lo:
            total += hi - lo
    return total


class Run:
    def __init__(self, test, out, args, arch=None):
        self.out = out
        if isinstance(arch, dict):
            arch_path = os.path.join(out, "arch.json")
            os.makedirs(out, exist_ok=True)
            with open(arch_path, "w") as f:
                json.dump(arch, f)
            arch = arch_path
        cmd = [os.environ["OPRT_BINARY"], "render", ROOM, "--arch", arch or PAPER, "--no-progress",
               "--out", out, *args]
        r = subprocess.run(cmd, capture_output=True, text=True)
        test.assertEqual(r.returncode, 0, " ".join(cmd) + "\n" + r.stdout + r.stderr)
        with open(os.path.join(out, "stats.json")) as f:
            self.stats = json.load(f)
        self.cycle_ps = round(1e6 / self.stats["arch"]["clock_mhz"])


def timeline_slices(path):
    with open(path) as f:
        doc = json.load(f)
    names = {e["tid"]: e["args"]["name"] for e in doc["traceEvents"] if e["ph"] == "M" and e["name"] == "thread_name"}
    tracks = {}
    for e in doc["traceEvents"]:
        if e["ph"] != "X":
            continue
        for key in ("ts", "dur", "pid", "tid", "name"):
            assert key in e, e
        # Times are microseconds to the picosecond.
        tracks.setdefault(names[e["tid"]], []).append(
            (round(e["ts"] * 1e6), round(e["dur"] * 1e6), e["name"], e.get("args", {})))
    return tracks


class TestTimeline(unittest.TestCase):
    def check_against_stats(self, run, tracks):
        frame = run.stats["frames"][0]
        for iu in frame["ius"]:
            slices = tracks[f"IU {iu['id']}"]
            slices.sort()
            for a, b in zip(slices, slices[1:]):
                self.assertLessEqual(a[0] + a[1], b[0], "slices of one unit overlap")
            cycles = {p: 0 for p in PHASES}
            rays, single = 0, set()
            for ts, dur, name, args in slices:
                self.assertEqual(dur % run.cycle_ps, 0)
                cycles["stall" if name == "bus wait" else name] += dur // run.cycle_ps
                if "rays" in args:
                    rays += args["rays"]
                    self.assertEqual(name, "sphere")
                else:
                    single.add(args["ray"])
            # The slices add up to the unit's cycles, phase by phase, and cover each ray it saw.
            self.assertEqual(cycles, {p: iu["cycles"][p] for p in PHASES}, f"IU {iu['id']}")
            self.assertEqual(rays + len(single), iu["rays"], f"IU {iu['id']}")
        return frame

    def test_ideal_units_running_ahead(self):
        with tempfile.TemporaryDirectory() as d:
            run = Run(self, d, ["--frames", "0", "--resolution", "32x32", "--timeline", os.path.join(d, "t.json")])
            tracks = timeline_slices(os.path.join(d, "t.json"))
            frame = self.check_against_stats(run, tracks)
            # The GPP and the bus take no time under the paper's ideal assumptions: the frame only.
            self.assertEqual([s[2] for s in tracks["GPP"]], ["frame"])
            self.assertEqual(tracks["GPP"][0][1], frame["makespan_cycles"] * run.cycle_ps)
            self.assertNotIn("bus", tracks)

    def test_contended_bus_gpp_and_memory(self):
        with tempfile.TemporaryDirectory() as d:
            run = Run(self, d, ["--frames", "10", "--resolution", "24x24", "--timeline", os.path.join(d, "t.json")],
                      CONTENDED)
            tracks = timeline_slices(os.path.join(d, "t.json"))
            frame = self.check_against_stats(run, tracks)
            gpp = tracks["GPP"]
            # The GPP's work on a ray is named by the ray's kind: one issue slice per ray of
            # each kind, one shade slice per primary hit (the paper's scenes reflect nothing).
            for kind in ("primary", "shadow"):
                issues = [s for s in gpp if s[2] == "issue " + kind]
                self.assertEqual(len(issues), frame["rays"][kind])
                self.assertTrue(all(s[1] == 4 * run.cycle_ps for s in issues))
            self.assertEqual({s[2] for s in gpp} - {"frame", "issue primary", "issue shadow", "shade primary"}, set())
            self.assertTrue(all(s[1] == 30 * run.cycle_ps for s in gpp if s[2] == "shade primary"))
            self.assertGreater(len([s for s in gpp if s[2] == "shade primary"]), 0)
            # Within the frame (before it, the set-up loads the object memories).
            start = [s[0] for s in gpp if s[2] == "frame"][0]
            bus = [s for s in tracks["bus"] if s[0] >= start]
            self.assertEqual(sum(s[1] for s in bus), frame["bus"]["busy_cycles"] * run.cycle_ps)
            self.assertEqual({s[2] for s in bus}, {"config", "ray", "answer"})
            self.assertEqual({s[2] for s in tracks["bus"] if s[0] < start}, {"memory load"})


class TestWaveforms(unittest.TestCase):
    def test_fst_reads_back_as_the_vcd_and_holds_the_stats(self):
        fst2vcd, vcd2fst = gtkwave_tool("fst2vcd"), gtkwave_tool("vcd2fst")
        with tempfile.TemporaryDirectory() as d:
            args = ["--frames", "10:11", "--resolution", "24x24", "--level", "at"]
            run = Run(self, os.path.join(d, "vcd"), args + ["--vcd", os.path.join(d, "t.vcd")], CONTENDED)
            Run(self, os.path.join(d, "fst"), args + ["--vcd", os.path.join(d, "t.fst")], CONTENDED)
            with open(os.path.join(d, "t.gtkw")) as f:
                self.assertIn(os.path.join(d, "t.fst"), f.read())  # the same save file, for the FST
            subprocess.run([fst2vcd, "-f", os.path.join(d, "t.fst"), "-o", os.path.join(d, "from_fst.vcd")],
                           check=True, capture_output=True)
            subprocess.run([vcd2fst, os.path.join(d, "t.vcd"), os.path.join(d, "again.fst")], check=True,
                           capture_output=True)
            subprocess.run([fst2vcd, "-f", os.path.join(d, "again.fst"), "-o", os.path.join(d, "again.vcd")],
                           check=True, capture_output=True)
            vcd = parse_vcd(os.path.join(d, "t.vcd"))
            self.assertEqual(parse_vcd(os.path.join(d, "from_fst.vcd")), vcd)
            self.assertEqual(parse_vcd(os.path.join(d, "again.vcd")), vcd)
            self.assertLess(os.path.getsize(os.path.join(d, "t.fst")), os.path.getsize(os.path.join(d, "t.vcd")) / 3)

            # Chosen signals at chosen times, against the stats: the GPP's frame number and
            # rays in flight at each frame's end, every unit's time per state within each
            # frame, the bus's busy time.
            engine = "testbench.engine."
            frame_sig, in_flight = vcd[engine + "gpp.frame"], vcd[engine + "gpp.rays_in_flight"]
            starts = [t for t, v in frame_sig if v in (10, 11)]
            self.assertEqual([v for t, v in frame_sig if t in starts], [10, 11])
            ends = [starts[1], vcd["#end"]]
            fst = parse_vcd(os.path.join(d, "from_fst.vcd"))
            for f, start, end in zip(run.stats["frames"], starts, ends):
                self.assertEqual(end - start, f["makespan_cycles"] * run.cycle_ps)
                self.assertEqual(value_at(fst[engine + "gpp.frame"], start), f["frame"])
                self.assertEqual(value_at(in_flight, end), 0)
                for iu in f["ius"]:
                    state = fst[f"{engine}iu{iu['id']}.state"]
                    for code, phase in enumerate(PHASES, start=1):
                        self.assertEqual(time_in(state, code, start, end), iu["cycles"][phase] * run.cycle_ps,
                                         f"frame {f['frame']} IU {iu['id']} {phase}")
                    self.assertEqual(time_in(state, 0, start, end), iu["cycles"]["idle"] * run.cycle_ps)
                    self.assertEqual(value_at(fst[f"{engine}fifo{iu['id']}.occupancy"], end), 0)
                self.assertEqual(time_in(fst[engine + "bus.busy"], 1, start, end),
                                 f["bus"]["busy_cycles"] * run.cycle_ps)


class TestSelections(unittest.TestCase):
    """A selected trace is the full trace restricted to what was selected."""

    def full(self, d, args):
        Run(self, os.path.join(d, "full"), args + ["--vcd", os.path.join(d, "full.vcd"),
                                                   "--timeline", os.path.join(d, "full.json")])
        return parse_vcd(os.path.join(d, "full.vcd"))

    def check_restricted(self, part, full, start, end, signals=None):
        """`part` starts at `start` with the full trace's values then, has its changes up to
        `end` (a window excludes its end; the run's end is in both) and ends there."""
        names = [n for n in full if n != "#end"] if signals is None else signals
        self.assertEqual(sorted(n for n in part if n != "#end"), sorted(names))
        self.assertEqual(part["#end"], end)
        last = end if end == full["#end"] else end - 1
        for n in names:
            self.assertEqual(part[n][0], (start, value_at(full[n], start)), n)
            self.assertEqual(part[n][1:], [(t, v) for t, v in full[n] if start < t <= last], n)

    def test_units_and_signal_groups(self):
        with tempfile.TemporaryDirectory() as d:
            args = ["--frames", "0", "--resolution", "24x24"]
            full = self.full(d, args)
            Run(self, os.path.join(d, "part"), args + ["--vcd", os.path.join(d, "part.vcd"), "--timeline",
                                                       os.path.join(d, "part.json"), "--trace-units", "1,3",
                                                       "--trace-signals", "state,gpp"])
            e = "testbench.engine."
            chosen = [e + "iu1.state", e + "iu3.state", e + "gpp.rays_in_flight", e + "gpp.frame", e + "gpp.ray_kind"]
            self.check_restricted(parse_vcd(os.path.join(d, "part.vcd")), full, 0, full["#end"], chosen)
            with open(os.path.join(d, "part.gtkw")) as f:
                listed = [l.strip() for l in f if l.startswith(e)]
            self.assertEqual(listed, [e + "gpp.rays_in_flight[31:0]", e + "gpp.frame[31:0]", e + "gpp.ray_kind[1:0]",
                                      e + "iu1.state[2:0]", e + "iu3.state[2:0]"])
            self.assertEqual(sorted(timeline_slices(os.path.join(d, "part.json"))), ["GPP", "IU 1", "IU 3"])

    def test_time_window(self):
        with tempfile.TemporaryDirectory() as d:
            args = ["--frames", "0", "--resolution", "24x24"]
            full = self.full(d, args)
            Run(self, os.path.join(d, "part"), args + ["--vcd", os.path.join(d, "part.vcd"), "--timeline",
                                                       os.path.join(d, "part.json"), "--trace-window", "2us:7.5us"])
            part = parse_vcd(os.path.join(d, "part.vcd"))
            self.check_restricted(part, full, 2_000_000, 7_500_000)
            self.assertGreater(sum(len(c) for n, c in part.items() if n != "#end"), 100)  # the window holds work
            whole = timeline_slices(os.path.join(d, "full.json"))
            for track, slices in timeline_slices(os.path.join(d, "part.json")).items():
                clipped = sorted((max(ts, 2_000_000), min(ts + dur, 7_500_000)) for ts, dur, _, _ in whole[track]
                                 if ts < 7_500_000 and ts + dur > 2_000_000)
                self.assertEqual(sorted((ts, ts + dur) for ts, dur, _, _ in slices), clipped, track)

    def test_frames(self):
        with tempfile.TemporaryDirectory() as d:
            args = ["--frames", "0:2", "--resolution", "16x16"]
            full = self.full(d, args)
            Run(self, os.path.join(d, "part"), args + ["--vcd", os.path.join(d, "part.vcd"), "--trace-frames", "1"])
            frame = full["testbench.engine.gpp.frame"]
            start = [t for t, v in frame if v == 1][0]
            end = [t for t, v in frame if v == 2][0]
            self.check_restricted(parse_vcd(os.path.join(d, "part.vcd")), full, start, end)
            with open(os.path.join(d, "part.gtkw")) as f:
                self.assertIn(f"[timestart] {start}\n", f.read())


if __name__ == "__main__":
    unittest.main()
