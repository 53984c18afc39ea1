"""--accel bvh against brute force on the paper's two scenes: total IU busy cycles, balance and
wall time. Prints the markdown tables of docs/results.md ("BVH inside the spheres").

  scripts/bvh_results [--resolution 256x256] [--frame 0]

Every run: 32 IUs, testbench/arch/paper.json (the paper's ideal architecture), one frame.
Policies: `paper` (one sphere per IU in scene order), and `sa_n` (the room with --subdivide 8,
polygons without). For each sa_n run with a BVH it also says how well the sa_n weights
predict the measured per-sphere cycles (Pearson r), for the bvh-aware weights the model uses
and for the brute-force SA x N form, and what makespan the latter would give: the LPT
assignment on those weights, loaded with the measured per-sphere cycles (an estimate: shadow
rays stop at their first occluder, so a sphere's work depends slightly on its companions).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from .. import paths
from ..stats import pearson

OPRT = paths.oprt_binary()
ARCH = os.path.join(paths.ARCH, "paper.json")
SCENES = {"paper_room": ["--subdivide", "8"], "paper_polygons": []}


def run(args, out):
    cmd = [OPRT, *args, "--out", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode:
        sys.exit(f"bvh_results: {' '.join(cmd)} failed:\n{r.stdout}{r.stderr}")
    name = "stats.json" if args[0] == "render" else "reference.json"
    with open(os.path.join(out, name)) as f:
        return json.load(f)


def lpt_makespan(weights, cycles, units):
    """Longest-processing-time greedy on `weights` (ties: lower index, lower unit), as
    model/balance/assign.cpp; returns the largest unit total of `cycles`."""
    order = sorted(range(len(weights)), key=lambda i: (-weights[i], i))
    w, c = [0.0] * units, [0] * units
    for i in order:
        u = min(range(units), key=lambda k: (w[k], k))
        w[u] += weights[i]
        c[u] += cycles[i]
    return max(c)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--resolution", default="256x256")
    p.add_argument("--frame", default="0")
    a = p.parse_args(argv)
    common = ["--frames", a.frame, "--resolution", a.resolution]
    rows, balance, walls = [], [], []
    with tempfile.TemporaryDirectory(prefix="oprt_bvh_") as tmp:
        for scene, subdivide in SCENES.items():
            path = os.path.join(paths.SCENES, scene + ".json")
            render = ["render", path, "--arch", ARCH, "--no-progress", *common]
            r = {}
            for accel in ("brute", "bvh"):
                ref = run(["reference", path, "--accel", accel, *common], os.path.join(tmp, f"{scene}_ref_{accel}"))
                r[accel, "paper"] = run([*render, "--accel", accel], os.path.join(tmp, f"{scene}_{accel}"))
                r[accel, "sa_n"] = run([*render, "--accel", accel, "--balance", "sa_n", *subdivide],
                                       os.path.join(tmp, f"{scene}_san_{accel}"))
                walls.append((scene, accel, ref["frames"][0]["wall_s"], r[accel, "paper"]["frames"][0]["wall_s"]))
            for accel in ("brute", "bvh"):
                f = r[accel, "paper"]["frames"][0]
                parts = {k: sum(u["cycles"].get(k, 0) for u in f["ius"]) for k in ("sphere", "transform", "box", "primitive")}
                rows.append((scene, accel, f["busy_cycles"], parts))
            for policy in ("paper", "sa_n"):
                for accel in ("brute", "bvh"):
                    s = r[accel, policy]
                    f = s["frames"][0]
                    extra = ""
                    if policy == "sa_n" and accel == "bvh":
                        meas = f["sphere_cycles"]
                        spheres = s["sphere_list"]
                        plain = [x["sa_n_weight"] for x in r["brute", "sa_n"]["sphere_list"]]  # SA x N form
                        aware = [x["sa_n_weight"] for x in spheres]
                        extra = (f"r(bvh-aware weights) {pearson(aware, meas):.3f}, r(SA x N weights) "
                                 f"{pearson(plain, meas):.3f}; SA x N weights would give a makespan of about "
                                 f"{lpt_makespan(plain, meas, s['units']):,} cycles")
                    balance.append((scene, policy + (" --subdivide 8" if policy == "sa_n" and subdivide else ""),
                                    accel, s["spheres"], f["makespan_cycles"], f["parallel_efficiency"],
                                    f["busy_cycles"], extra))
    print("| scene | accel | total IU busy cycles | sphere | transform | box | primitive | brute / bvh |")
    print("|---|---|---|---|---|---|---|---|")
    for i, (scene, accel, busy, parts) in enumerate(rows):
        ratio = f"{rows[i - 1][2] / busy:.2f}x" if accel == "bvh" else ""
        print(f"| {scene} | {accel} | {busy:,} | " + " | ".join(f"{parts[k]:,}" for k in parts) + f" | {ratio} |")
    print("\n| scene | policy | accel | spheres | makespan (cycles) | parallel efficiency | total busy |")
    print("|---|---|---|---|---|---|---|")
    for scene, policy, accel, spheres, makespan, eff, busy, extra in balance:
        print(f"| {scene} | {policy} | {accel} | {spheres} | {makespan:,} | {eff:.3f} | {busy:,} |")
    for scene, policy, accel, *_, extra in balance:
        if extra:
            print(f"\n{scene}, {policy}, bvh: {extra}")
    print("\n| scene | accel | reference wall (s) | render --level at wall (s) |")
    print("|---|---|---|---|")
    for scene, accel, ref_wall, at_wall in walls:
        print(f"| {scene} | {accel} | {ref_wall:.2f} | {at_wall:.2f} |")
    return 0

