"""Rays only where they are needed (issue 21, docs/results.md "Routing"): for each scene, route
(broadcast, multicast, ordered) and assignment (sa_n; spatial at locality 1, tight bounds;
spatial at its default, the knob's middle, 0.5; feedback at locality 0.5), it runs

  oprt render SCENE --frames F [--resolution R] --subdivide K --ius 32 --accel bvh --top bvh
       --route ROUTE --balance B [--locality L] --level analytic --tech testbench/tech/45nm.json

(otherwise the paper's architecture: ideal bus, GPP and memories, unbounded FIFOs) and prints one
markdown row per run, means over the frames (the room and the polygons: frame 1 of 0:1, so that
feedback has measured a frame): total unit busy cycles, makespan, parallel
efficiency, fan-out (units per ray), bus bytes per ray, router cycles per ray, units `ordered`
skipped per ray, energy per frame; and the same figures as JSON (--json FILE) for
scripts/plot_route. Every image of a scene must be the same across routes and assignments
(checked, frame by frame).

  scripts/route_results [--out DIR] [--oprt PATH] [--scenes room1,room8,polygons,kitchen] [--json FILE] [--replicate]

--replicate (issue 27, docs/results.md "Replicated spheres"): instead, the router with a box per
visible sphere and 64 lanes, routes multicast and ordered, assignments feedback at locality 1 and
0.5, each without and with --replicate auto; and per row the copies' extra bytes against the
scene's geometry bytes (the largest over the frames).
"""
import json
import os
import sys

from .. import paths
from ..render import render, script_arguments
from ..stats import frame_rays


# name: (scene, frames rendered, frames reported from (feedback re-partitions from the second
# frame on), resolution or None for the scene's own, K)
SCENES = {
    "room1": (os.path.join(paths.SCENES, "paper_room.json"), "0:1", 1, None, 1),
    "room8": (os.path.join(paths.SCENES, "paper_room.json"), "0:1", 1, None, 8),
    "room8x30": (os.path.join(paths.SCENES, "paper_room.json"), "0:29", 0, None, 8),
    "polygons": (os.path.join(paths.SCENES, "paper_polygons.json"), "0:1", 1, None, 8),
    "kitchen": (os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff"), "0:29", 0, "128x96", 1),
}
ROUTES = ("broadcast", "multicast", "ordered")
BALANCES = (("sa_n", []), ("spatial 1", ["--locality", "1"]), ("spatial 0.5", []), ("feedback 0.5", ["--locality", "0.5"]))
REPLICATED = (("feedback 1", ["--locality", "1"]), ("feedback 1 +copies", ["--locality", "1", "--replicate", "auto"]),
              ("feedback 0.5", ["--locality", "0.5"]),
              ("feedback 0.5 +copies", ["--locality", "0.5", "--replicate", "auto"]))


def figures(stats, skip):
    frames = stats["frames"][skip:]
    n = len(frames)
    rays = sum(frame_rays(f) for f in frames)
    mean = lambda key: sum(f[key] for f in frames) / n
    return {
        "busy_cycles": mean("busy_cycles"),
        "makespan_cycles": mean("makespan_cycles"),
        "parallel_efficiency": mean("parallel_efficiency"),
        "fanout_mean": sum(f["route"]["fanout_mean"] * frame_rays(f) for f in frames) / rays,
        "fanout_max": max(f["route"]["fanout_max"] for f in frames),
        "bus_bytes_per_ray": sum(f["bus"]["bytes"] for f in frames) / rays,
        "route_cycles_per_ray": sum(f["route"]["cycles"] for f in frames) / rays,
        "skipped_per_ray": sum(f["route"]["skipped"] for f in frames) / rays,
        "energy_j": sum(f["energy_j"]["total"] for f in frames) / n,
        "hashes": [f["image_hash"] for f in frames],
        "copy_bytes": max((f["replicas"]["bytes"] for f in frames if "replicas" in f), default=0),
        "geometry_bytes": max((f["replicas"]["geometry_bytes"] for f in frames if "replicas" in f), default=0),
    }


def main(argv=None):
    ap = script_arguments(__doc__, "route_results")
    ap.add_argument("--scenes", default="room1,room8,polygons,kitchen")
    ap.add_argument("--json", help="write every row's figures here as well")
    ap.add_argument("--replicate", action="store_true", help="the replication rows (issue 27)")
    a = ap.parse_args(argv)
    tech = os.path.join(paths.TECH, "45nm.json")
    routes, balances, arch = ROUTES, BALANCES, {}
    if a.replicate:
        routes, balances = ("multicast", "ordered"), REPLICATED
        os.makedirs(a.out, exist_ok=True)
        for route in routes:
            arch[route] = os.path.join(a.out, f"{route}_sphere_64.json")
            with open(arch[route], "w") as fp:
                json.dump({"format": "oprt-arch/1", "route": {"policy": route, "bound": "sphere", "lanes": 64}}, fp)
    rows = []
    print("| scene | route | assignment | busy (Mcycles) | makespan (Mcycles) | efficiency | fan-out (mean / max) "
          "| bus bytes / ray | router cycles / ray | skipped / ray | energy (mJ/frame) |" + (" copies' bytes |" if a.replicate else ""))
    print("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|" if a.replicate else ""))
    for name in a.scenes.split(","):
        path, frames, skip, res, k = SCENES[name]
        hashes = None
        for route in routes:
            for balance, extra in balances:
                policy = balance.split()[0]
                args = [path, "--frames", frames, "--subdivide", str(k), "--ius", "32", "--accel", "bvh", "--top", "bvh",
                        "--route", route, "--balance", policy, "--level", "analytic", "--tech", tech] + extra
                if res:
                    args += ["--resolution", res]
                if route in arch:
                    args += ["--arch", arch[route]]
                out = os.path.join(a.out, name, route, balance.replace(" ", "_"))
                f = figures(render(args, out, a.oprt, "route_results"), skip)
                if hashes is None:
                    hashes = f["hashes"]
                elif f["hashes"] != hashes:
                    sys.exit(f"route_results: {name} {route} {balance}: the image differs from the first run's")
                f.update(scene=name, route=route, balance=balance, frames=frames if not skip else frames.split(":")[1], k=k,
                         resolution=res)
                rows.append(f)
                print(f"| {name} | {route} | {balance} | {f['busy_cycles'] / 1e6:.1f} | {f['makespan_cycles'] / 1e6:.2f} "
                      f"| {f['parallel_efficiency']:.3f} | {f['fanout_mean']:.2f} / {f['fanout_max']} "
                      f"| {f['bus_bytes_per_ray']:.0f} | {f['route_cycles_per_ray']:.1f} | {f['skipped_per_ray']:.2f} "
                      f"| {f['energy_j'] * 1e3:.3f} |" +
                      (f" {f['copy_bytes']:,} ({100 * f['copy_bytes'] / max(f['geometry_bytes'], 1):.2f} %) |"
                       if a.replicate else ""), flush=True)
    if a.json:
        with open(a.json, "w") as fp:
            json.dump(rows, fp, indent=1)

