"""Object memories with a capacity (--sram): the tables of docs/results.md. For each scene it runs

  oprt render SCENE --frames F --resolution R --accel A --top T --sram S

for S in unlimited (0), 16K, 64K and 256K per unit, with the default caches (64-byte lines, 4
ways, LRU, 4 misses in flight per unit) and DRAM (40 cycles, 16 bytes per cycle, 4 units per
channel), and prints per S: the units whose spheres did not fit, the caches' hit rate (line
lookups), misses, bytes from DRAM, the share of the units' time spent waiting for object memory
(memory stall / (busy + memory stall), all units), and the makespan against the unlimited
memory's; it checks that every image is the unlimited memory's. Scenes: paper_room (the
paper's unit: brute force, flat), the BART kitchen and a 1M-triangle grid of triangle clouds
(scripts/scale's, written into OUT), both with --accel bvh --top bvh.

  scripts/cache_results [--frames A:B] [--out DIR] [--oprt PATH] [--level at|lt|analytic]
                        [--scenes paper_room,kitchen,grid_1m]
"""
import os
import sys

from .. import paths
from ..render import chosen_scenes, render, scenes_present, script_arguments
from .scale import grid_scene


def figures(stats):
    hits = misses = dram = stall = busy = caches = makespan = 0
    for fr in stats["frames"]:
        makespan += fr["makespan_cycles"]
        for u in fr["ius"]:
            m = u["memory"]
            hits += m["hits"]
            misses += m["misses"]
            dram += m["dram_bytes"]
            stall += m["stall_cycles"]
            busy += u["busy_cycles"]
            caches = max(caches, sum(1 for v in fr["ius"] if v["memory"]["cache"]))
    return dict(hits=hits, misses=misses, dram=dram, stall=stall, busy=busy, caches=caches, makespan=makespan,
                units=stats["units"], hashes=[fr["image_hash"] for fr in stats["frames"]],
                assigned=sorted(u["memory"]["assigned_bytes"] for u in stats["frames"][0]["ius"]))


def main(argv=None):
    ap = script_arguments(__doc__, "cache_results", frames="0:1", level="at")
    ap.add_argument("--scenes", default="paper_room,kitchen,grid_1m", help="which of the three (default: all)")
    a = ap.parse_args(argv)
    wanted = chosen_scenes(a.scenes, ("paper_room", "kitchen", "grid_1m"), "cache_results")
    os.makedirs(a.out, exist_ok=True)
    grid = os.path.join(a.out, "grid_1m.json")
    if "grid_1m" in wanted:
        grid_scene(grid, 10, 1000)  # 1,000 clouds of 1,000 triangles: 48 MB of triangles
    cases = [("paper_room", os.path.join(paths.SCENES, "paper_room.json"), "256x256", ["--accel", "brute"]),
             ("kitchen", os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff"), "256x192",
              ["--accel", "bvh", "--top", "bvh"]),
             ("grid 1M", grid, "256x256", ["--accel", "bvh", "--top", "bvh"])]
    print("| scene | accel, top | object memory per unit | units with a cache | hit rate | misses | from DRAM (MB) "
          "| waiting for memory | makespan (M cycles) | / unlimited |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    cases = [c for c in cases if c[0].replace(" ", "_") in wanted]
    for name, scene, res, extra in scenes_present(cases, "cache_results"):
        base = None
        for sram in ("0", "16K", "64K", "256K"):
            out = os.path.join(a.out, f"{name.replace(' ', '_')}_{sram}")
            s = render([scene, "--frames", a.frames, "--resolution", res, "--level", a.level, "--sram", sram] + extra,
                       out, a.oprt, "cache_results")
            f = figures(s)
            if base is None:
                base = f
                print(f"cache_results: {name}: {f['units']} units need {f['assigned'][0] / 1024:,.0f} to "
                      f"{f['assigned'][-1] / 1024:,.0f} KiB each", file=sys.stderr)
            elif f["hashes"] != base["hashes"]:
                sys.exit(f"cache_results: {out}: the image differs from the unlimited memory's")
            lookups = f["hits"] + f["misses"]
            print(f"| {name} | {extra[1]}{', ' + extra[3] if len(extra) > 2 else ', flat'} "
                  f"| {'unlimited' if sram == '0' else sram + 'B'} | {f['caches']} of {f['units']} "
                  f"| {f['hits'] / lookups if lookups else float('nan'):.3f} | {f['misses']:,} | {f['dram'] / 1e6:,.1f} "
                  f"| {f['stall'] / max(1, f['busy'] + f['stall']):.2%} | {f['makespan'] / 1e6:,.3f} "
                  f"| {f['makespan'] / base['makespan']:.4f} |")
    print(f"\n(frames {a.frames} summed, level {a.level}; every image equal to the unlimited memory's; outputs in {a.out})")

