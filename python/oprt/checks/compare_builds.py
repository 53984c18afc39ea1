"""Two oprt builds side by side: the same renders (at, lt, analytic x the ideal and contended
architectures, pipelined units, routes, caches, DRAM channels shared over the bus, GPP costs;
the room at 32x32, 8 units) with each, and their stats.json (wall times aside), EXRs, VCDs and
timelines compared byte for byte. Run from the project root:
  scripts/compare_builds OLD_OPRT NEW_OPRT      (exit 1 if any output differs)
For a change that must not move a figure (a refactor, a speed-up)."""
import json
import os
import subprocess
import sys
import tempfile

SCENE = "scenes/paper_room.json"
# Heavy contention: FIFOs of 4, GPP costs, a shared bus with arbitration, memory latency and
# DRAM channels shared over the bus.
HEAVY = ('{\n  "format": "oprt-arch/1",\n  "ius": 8,\n  "ray_fifo_depth": 4,\n'
         '  "gpp": {"cycles_per_ray": 4, "cycles_per_hit": 30, "cycles_per_node": 3},\n'
         '  "bus": {"model": "shared", "bytes_per_cycle": 8, "arbitration_cycles": 1},\n'
         '  "memory": {"model": "latency", "latency_cycles": 10, "bytes_per_cycle": 16, '
         '"dram": {"units_per_channel": 2, "path": "bus"}}\n}\n')
CONTENDED = "testbench/arch/contended.json"


def configs(heavy):
    """The 39 command lines (13 per level); TL and VCD stand for a timeline and a VCD file."""
    extras = [
        [], ["--arch", CONTENDED],
        ["--iu", "pipelined", "--arch", CONTENDED],
        ["--route", "multicast", "--balance", "spatial", "--accel", "bvh", "--top", "bvh"],
        ["--route", "ordered", "--balance", "spatial", "--accel", "bvh", "--arch", CONTENDED, "--iu", "pipelined"],
        ["--route", "ordered", "--balance", "spatial", "--accel", "bvh", "--arch", CONTENDED],
        ["--sram", "4K", "--accel", "bvh", "--arch", CONTENDED],
        ["--sram", "4K", "--iu", "pipelined"],
        ["--balance", "feedback", "--subdivide", "2", "--frames", "0:2"],
        ["--arch", heavy, "--sram", "2K", "--accel", "bvh", "--top", "bvh", "--route", "ordered", "--balance", "spatial"],
        ["--arch", heavy, "--sram", "2K", "--iu", "pipelined", "--route", "multicast", "--balance", "feedback",
         "--frames", "0:1"],
        ["--arch", heavy, "--route", "multicast", "--balance", "spatial", "--timeline", "TL"],
        ["--arch", heavy, "--route", "ordered", "--top", "bvh", "--balance", "spatial", "--vcd", "VCD"],
    ]
    return [["--level", level] + extra for level in ("at", "lt", "analytic") for extra in extras]


def strip(o):
    """stats.json without what measures wall time."""
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if "wall" not in k and "seconds" not in k and "time_s" not in k}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o


def differences(x, y, p, diffs):
    """Appends to diffs the JSON paths (from p) where x and y differ."""
    if type(x) != type(y):
        diffs.append(p)
    elif isinstance(x, dict):
        for k in set(x) | set(y):
            differences(x.get(k), y.get(k), p + "/" + k, diffs)
    elif isinstance(x, list):
        if len(x) != len(y):
            diffs.append(p + " len")
            return diffs
        for i, (u, v) in enumerate(zip(x, y)):
            differences(u, v, p + f"[{i}]", diffs)
    elif x != y:
        diffs.append(f"{p}: {x} != {y}")
    return diffs


def outputs(binary, args):
    """(stats.json stripped, {file: bytes} of the other outputs) of one render, or None if it failed."""
    d = tempfile.mkdtemp()
    a2 = [x.replace("TL", d + "/t.json").replace("VCD", d + "/w.vcd") for x in args]
    r = subprocess.run([binary, "render", SCENE, "--resolution", "32x32", "--ius", "8", "--no-progress", "--out", d] + a2,
                       capture_output=True, text=True)
    if r.returncode:
        print("FAIL", binary, args, r.stderr[-500:])
        return None
    with open(os.path.join(d, "stats.json")) as f:
        st = strip(json.load(f))
    exr = {}
    for name in os.listdir(d):
        if name.endswith((".exr", ".json", ".vcd")) and name != "stats.json":
            with open(os.path.join(d, name), "rb") as f:
                exr[name] = f.read()
    return st, exr


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        sys.exit(__doc__)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as heavy:
        heavy.write(HEAVY)
    todo = configs(heavy.name)
    bad = 0
    for c in todo:
        args = c if "--frames" in c else c + ["--frames", "1"]
        outs = [outputs(binary, args) for binary in argv]
        bad += outs.count(None)
        if None in outs:
            continue
        if outs[0] == outs[1]:
            print("same", " ".join(args))
            continue
        bad += 1
        diffs = differences(outs[0][0], outs[1][0], "", [])
        print("DIFF", args, diffs[:8], "exr same" if outs[0][1] == outs[1][1] else "EXR DIFF")
    os.unlink(heavy.name)
    print("different or failed:", bad, "of", len(todo), "(analytic with --vcd or --timeline is refused by both: expected)")
    return 1 if bad > 4 else 0
