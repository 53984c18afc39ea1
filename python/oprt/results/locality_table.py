"""What --balance spatial buys against sa_n (issue 21): the table of docs/results.md. For each
scene and assignment it runs

  oprt info SCENE --subdivide K --ius N --balance P [--locality F] --accel A

and reads the two estimates it prints (model/balance/partition_quality.h): the fan-out, the
expected number of units a ray entering the scene's box enters when each unit is bounded by
the box of its spheres at frame 0, and the imbalance, the largest unit's sa_n cost over the
mean. With --measure it also renders frame 0 under today's broadcast at --level analytic and
reports the measured parallel efficiency (the mean unit's busy cycles over the busiest's), to
show how far the sa_n estimate of balance carries.

With --animation FRAMES it instead renders the room over those frames (broadcast, --level
analytic) under sa_n, spatial, feedback and feedback --locality 0.25 / 0.5 / 0.75, and reports
per run the mean parallel efficiency, mean makespan, mean busy cycles of all units and the
geometry the policy moved over the bus.

  scripts/locality_table [--ius N] [--subdivide K] [--measure] [--resolution WxH] [--oprt PATH]
  scripts/locality_table --animation 0:29 [--ius N] [--subdivide K] [--resolution WxH]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

from .. import paths

SCENES = ["paper_room", "paper_polygons"]
POLICIES = [("sa_n", []), *[(f"spatial {f}", ["--locality", f]) for f in ("0", "0.25", "0.5", "0.75", "1")]]


def oprt(binary, args):
    r = subprocess.run([binary] + args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"locality_table: {' '.join([binary] + args)} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
    return r.stdout


def estimates(binary, scene, policy, extra, accel, a):
    out = oprt(binary, ["info", scene, "--subdivide", str(a.subdivide), "--ius", str(a.ius),
                        "--balance", policy.split()[0], *extra, "--accel", accel])
    return (float(re.search(r"fan-out ([0-9.]+)", out).group(1)),
            float(re.search(r"imbalance ([0-9.]+)", out).group(1)))


def efficiency(binary, scene, policy, extra, accel, a, tmp):
    out = os.path.join(tmp, "run")
    oprt(binary, ["render", scene, "--frames", "0", "--resolution", a.resolution, "--level", "analytic",
                  "--subdivide", str(a.subdivide), "--ius", str(a.ius), "--balance", policy.split()[0], *extra,
                  "--accel", accel, "--no-progress", "--out", out])
    with open(os.path.join(out, "stats.json")) as f:
        return json.load(f)["frames"][0]["parallel_efficiency"]


def animation(a):
    print("| accel | balance | efficiency | makespan (cycles) | busy cycles, all units | geometry moved (bytes) |")
    print("|---|---|---:|---:|---:|---:|")
    scene = os.path.join(paths.SCENES, "paper_room.json")
    policies = [["sa_n"], ["spatial"], ["feedback"]] + [["feedback", "--locality", f] for f in ("0.25", "0.5", "0.75")]
    with tempfile.TemporaryDirectory(prefix="oprt_locality_") as tmp:
        for accel in ("brute", "bvh"):
            for p in policies:
                out = os.path.join(tmp, "run")
                oprt(a.oprt, ["render", scene, "--frames", a.animation, "--resolution", a.resolution, "--level",
                              "analytic", "--subdivide", str(a.subdivide), "--ius", str(a.ius), "--balance", *p,
                              "--accel", accel, "--no-progress", "--out", out])
                with open(os.path.join(out, "stats.json")) as f:
                    frames = json.load(f)["frames"]
                n = len(frames)
                mean = lambda key: sum(fr[key] for fr in frames) / n
                print(f"| {accel} | {' '.join(p)} | {mean('parallel_efficiency'):.3f} | {mean('makespan_cycles'):,.0f} | "
                      f"{mean('busy_cycles'):,.0f} | {sum(fr['memory_load_bytes'] for fr in frames):,} |", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--oprt", default=paths.BUILD_OPRT)
    ap.add_argument("--ius", type=int, default=32)
    ap.add_argument("--subdivide", type=int, default=8)
    ap.add_argument("--measure", action="store_true")
    ap.add_argument("--resolution", default="256x256")
    ap.add_argument("--animation", metavar="FRAMES", help="the room over these frames, e.g. 0:29 (see above)")
    a = ap.parse_args(argv)
    if a.animation:
        return animation(a)
    head = ["scene", "assignment"]
    for accel in ("brute", "bvh"):
        head += [f"fan-out ({accel})", f"imbalance ({accel})"] + ([f"efficiency ({accel})"] if a.measure else [])
    print("| " + " | ".join(head) + " |")
    print("|" + "|".join("---" if i < 2 else "---:" for i in range(len(head))) + "|")
    with tempfile.TemporaryDirectory(prefix="oprt_locality_") as tmp:
        for name in SCENES:
            scene = os.path.join(paths.SCENES, name + ".json")
            for policy, extra in POLICIES:
                row = [name, policy]
                for accel in ("brute", "bvh"):
                    fanout, imbalance = estimates(a.oprt, scene, policy, extra, accel, a)
                    row += [f"{fanout:.2f}", f"{imbalance:.3f}"]
                    if a.measure:
                        row.append(f"{efficiency(a.oprt, scene, policy, extra, accel, a, tmp):.3f}")
                print("| " + " | ".join(row) + " |", flush=True)

