"""The tree over each unit's spheres (--top bvh) against the flat list (--top flat): the tables
of docs/results.md. For each scene and policy it runs

  oprt render SCENE --frames F --resolution R --balance P [--subdivide K] --accel A --top T

for A/T in brute/flat (the paper's unit), bvh/flat and bvh/bvh, and prints per configuration
the total IU busy cycles (summed over the frames) by activity, the mean makespan, the GPP's
refit cycles and the tree nodes built, checking that every image is the brute-force one.

  scripts/top_results [--frames A:B] [--resolution WxH] [--kitchen-resolution WxH] [--out DIR]
                      [--oprt PATH] [--level at|analytic]
"""
import os
import sys

from .. import paths
from ..render import render, scenes_present, script_arguments


def totals(stats):
    t = {k: 0 for k in ("sphere", "node", "transform", "box", "primitive")}
    busy = makespan = refit = built = 0
    hashes = []
    for fr in stats["frames"]:
        for u in fr["ius"]:
            for k in t:
                t[k] += u["cycles"].get(k, 0)
        busy += fr["busy_cycles"]
        makespan += fr["makespan_cycles"]
        refit += fr.get("gpp", {}).get("refit_cycles", 0)
        built += fr.get("gpp", {}).get("nodes_built", 0)
        hashes.append(fr["image_hash"])
    n = len(stats["frames"])
    return dict(t, busy=busy, makespan=makespan / n, refit=refit / n, built=built, hashes=hashes, frames=n)


def main(argv=None):
    ap = script_arguments(__doc__, "top_results", frames="0:9", resolution="256x256", kitchen_resolution="256x192",
                          level="at")
    a = ap.parse_args(argv)
    cases = [("paper_room", os.path.join(paths.SCENES, "paper_room.json"), a.resolution, ["--subdivide", "8"]),
             ("kitchen", os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff"), a.kitchen_resolution, [])]
    print("| scene | policy | accel | top | total busy (M cycles) | node | sphere | transform | box | primitive "
          "| mean makespan (M cycles) | GPP refit cycles per frame | nodes built | brute / this (busy) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, scene, res, extra in scenes_present(cases, "top_results"):
        for policy in ("sa_n", "feedback"):
            base = None
            for accel, top in (("brute", "flat"), ("bvh", "flat"), ("bvh", "bvh")):
                out = os.path.join(a.out, f"{name}_{policy}_{accel}_{top}")
                s = render([scene, "--frames", a.frames, "--resolution", res, "--balance", policy,
                            "--accel", accel, "--top", top, "--level", a.level] + extra, out, a.oprt, "top_results")
                t = totals(s)
                if base is None:
                    base = t
                elif t["hashes"] != base["hashes"]:
                    sys.exit(f"top_results: {out}: the image differs from brute force's")
                k = f" --subdivide {extra[1]}" if extra else ""
                print(f"| {name} | {policy}{k} | {accel} | {top} | {t['busy'] / 1e6:,.1f} | {t['node'] / 1e6:,.1f} "
                      f"| {t['sphere'] / 1e6:,.1f} | {t['transform'] / 1e6:,.1f} | {t['box'] / 1e6:,.1f} "
                      f"| {t['primitive'] / 1e6:,.1f} | {t['makespan'] / 1e6:,.2f} | {t['refit']:,.0f} | {t['built']:,} "
                      f"| {base['busy'] / t['busy']:.2f}x |")
    print(f"\n(frames {a.frames}, level {a.level}; every image equal to brute force's; outputs in {a.out})")

