"""Scale runs of `oprt render`: wall time and peak memory (the process's maximum resident set,
from wait4's rusage) for large generated scenes, and bytes per triangle from a series of scenes
that differ only in triangle count.

  scripts/scale [--oprt PATH] [--quick]

Scenes are written as small oprt-scene/1 files into a temporary directory: an N x N x N grid
of `triangle_cloud` objects (each its own bounding sphere), radius 0.3 at spacing 1, so a ray
crosses only a few spheres: without an acceleration structure a ray is tested against every
triangle of every sphere it enters, and scenes of big overlapping spheres would take hours.
Prints a Markdown table (docs/results.md, docs/reliability.md)."""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

from .. import paths
from ..stats import frame_rays


def grid_scene(path, per_side, triangles_each):
    objects = []
    half = (per_side - 1) / 2
    for i in range(per_side):
        for j in range(per_side):
            for k in range(per_side):
                objects.append({
                    "mesh": {"generate": {"kind": "triangle_cloud", "count": triangles_each, "radius": 0.3,
                                          "size": 0.05, "seed": 1 + len(objects)}},
                    "transform": {"translate": [i - half, j - half, k - half]},
                    "animation": {"keyframes": [{"frame": 0}, {"frame": 1, "rotate": {"axis": [0, 1, 0], "deg": 10}}]}})
    doc = {"format": "oprt-scene/1",
           "camera": {"eye": [0.35 * per_side, 0.45 * per_side, 2.2 * per_side], "target": [0, 0, 0], "up": [0, 1, 0],
                      "fov_y_deg": 45},
           "image": {"width": 256, "height": 256},
           "lights": [{"position": [2 * per_side, 3 * per_side, 3 * per_side], "color": [1, 1, 1]}],
           "objects": objects, "frames": 2}
    with open(path, "w") as f:
        json.dump(doc, f)
    return per_side ** 3 * triangles_each


def run_measured(oprt, args):
    """(wall seconds, peak RSS in bytes, stdout) of one run."""
    t0 = time.monotonic()
    p = subprocess.Popen([oprt] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = p.stdout.read().decode()
    err = p.stderr.read().decode()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    if status != 0:
        sys.exit(f"scale: oprt {' '.join(args)} failed (status {status}):\n{err}")
    return wall, usage.ru_maxrss * 1024, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--oprt", default=paths.BUILD_OPRT)
    ap.add_argument("--quick", action="store_true", help="smaller scenes and images (a smoke test of the script)")
    a = ap.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="oprt_scale_")
    q = a.quick

    rows = []

    def row(label, scene, extra):
        out = os.path.join(tmp, "out")
        wall, rss, _ = run_measured(a.oprt, ["render", scene, "--frames", "0", "--no-progress", "--out", out] + extra)
        with open(os.path.join(out, "stats.json")) as f:
            s = json.load(f)
        fr = s["frames"][0]
        rays = frame_rays(fr)
        rows.append((label, s["triangles"], s["objects"], s["units"], "x".join(map(str, s["resolution"])),
                     s["arch"]["level"], wall, rss, rays, fr["makespan_cycles"]))
        print(f"  {label}: {wall:.1f} s, {rss / 2**20:.0f} MiB", file=sys.stderr)
        return rss

    # Memory against triangles: the same 1,000-object grid, more triangles per object.
    per_side = 5 if q else 10
    series = [125, 250, 500, 1000] if not q else [10, 20, 40, 80]
    points = []
    for t in series:
        scene = os.path.join(tmp, f"grid_{t}.json")
        n = grid_scene(scene, per_side, t)
        rss = row(f"memory series, {n:,} triangles", scene, ["--level", "lt", "--resolution", "32x32", "--ius", "32"])
        points.append((n, rss))
    big = os.path.join(tmp, f"grid_{series[-1]}.json")
    res = "128x128" if q else "256x256"
    row("1M triangles, 1,000 objects, lt", big, ["--level", "lt", "--resolution", res, "--ius", "32"])
    row("256 IUs", big, ["--level", "lt", "--resolution", "64x64" if q else "128x128", "--ius", "256"])
    row("1024x1024", os.path.join(paths.SCENES, "paper_room.json"),
        ["--level", "lt", "--resolution", "256x256" if q else "1024x1024", "--ius", "32"])

    # Least squares: peak RSS = a + b x triangles.
    n = len(points)
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    b = sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)
    a0 = my - b * mx
    worst = max(abs(y - (a0 + b * x)) / y for x, y in points)

    print("| run | triangles | objects | IUs | resolution | level | wall (s) | peak RSS (MiB) | rays | makespan (cycles) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]:,} | {r[2]:,} | {r[3]} | {r[4]} | {r[5]} | {r[6]:.1f} | {r[7] / 2**20:.0f} | {r[8]:,} | {r[9]:,} |")
    print()
    print(f"Peak RSS = {a0 / 2**20:.1f} MiB + {b:.0f} bytes x triangles (least squares over the memory series; "
          f"largest deviation from the line {100 * worst:.1f}%).")

