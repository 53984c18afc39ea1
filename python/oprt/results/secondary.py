"""What reflection and refraction rays do to the engine (issue 29, docs/results.md "Reflection and
refraction rays"): for each BART scene (the kitchen, the museum), depth 0 to 5 and route
(broadcast, multicast, ordered) it runs

  oprt render SCENE --arch testbench/arch/paper.json --ius 32 --accel bvh --top bvh
       --balance spatial --route ROUTE --depth D --frames 0 --resolution 128x96 --level analytic

(the paper's architecture: Table 1 costs, ideal bus, GPP and memories, unbounded FIFOs; the
router's defaults: one box per unit, 8 lanes, a ray and a unit mask per transfer) and prints one
markdown row per run: rays per kind (P primary / S shadow / R reflection / T refraction), rays
per pixel, busy cycles per unit (mean / max), makespan, parallel efficiency, the units' work per
ray of each kind (cycles), fan-out per kind (units per ray), bus bytes per ray per kind (the ray
and its answers), the GPP's starved cycles (nothing to issue, waiting for answers) and the mean
spawn delay of each kind (from the parent's answer to the child's issue). The image of a scene
and depth must be the same under every route (checked).

Then, at the deepest depth, every route again at --level at: the makespan, busy cycles and
image must equal the analytic level's (checked; the other figures are printed side by side).

  scripts/secondary_results [--out DIR] [--oprt PATH] [--scenes kitchen,museum] [--depths 0:5]
                            [--arch FILE] [--level analytic|at] [--json FILE] [--plot PNG] [--pictures DIR]

--arch: another architecture (e.g. testbench/arch/contended.json: FIFOs of 4, a shared bus);
analytic is then no longer exact, so run it with --level at (no second check then).

--plot: parallel efficiency and makespan against depth, one line per route, a row per scene.
--pictures: frame 0 of each scene by `oprt reference` at depth 0 and at the deepest depth, side
by side in one PNG per scene (DIR/SCENE_depth0_depthN.png).
"""
import json
import os
import sys

from .. import paths, rays
from ..render import chosen_scenes, reference, render, scenes_present, script_arguments

SCENES = (("kitchen", os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff")),
          ("museum", os.path.join(paths.SHARED, "bart", "museum", "museum5.aff")))
ROUTES = ("broadcast", "multicast", "ordered")
WHO = "secondary_results"


def figures(stats):
    """The row's figures of frame 0 of a run."""
    f = stats["frames"][0]
    kinds = rays.rays(f)
    total = sum(kinds.values())
    work = rays.work_cycles(stats, f)
    if sum(work.values()) != f["busy_cycles"]:
        sys.exit(f"{WHO}: the units' work priced per kind ({sum(work.values()):,} cycles) is not their busy "
                 f"cycles ({f['busy_cycles']:,}): the per-kind work column would be wrong")
    busy = [u["busy_cycles"] for u in f["ius"]]
    width, height = stats["resolution"]
    return {
        "rays": kinds,
        "rays_per_pixel": total / (width * height),
        "busy_cycles": f["busy_cycles"],
        "busy_per_unit_mean": sum(busy) / len(busy),
        "busy_per_unit_max": max(busy),
        "makespan_cycles": f["makespan_cycles"],
        "parallel_efficiency": f["parallel_efficiency"],
        "work_cycles": work,
        "work_per_ray": {k: work[k] / kinds[k] if kinds[k] else None for k in rays.KINDS},
        "fanout_mean": rays.kind_figure(f, "fanout_mean"),
        "fanout_all": f["route"]["fanout_mean"],
        "bus_bytes_per_ray": rays.bus_bytes_per_ray(f),
        "bus_bytes_per_ray_all": f["bus"]["bytes"] / total,
        "gpp_starved_cycles": f["ray_kinds"]["gpp_starved_cycles"],
        "spawn_delay_cycles_mean": rays.kind_figure(f, "spawn_delay_cycles_mean"),
        "latency_cycles_mean": rays.kind_figure(f, "latency_cycles_mean"),
        "image_hash": f["image_hash"],
    }


def row(scene, depth, route, f):
    """One markdown row."""
    return (f"| {scene} | {depth} | {route} | {rays.cells(f['rays'])} | {f['rays_per_pixel']:.2f} "
            f"| {f['busy_per_unit_mean'] / 1e6:.2f} / {f['busy_per_unit_max'] / 1e6:.2f} "
            f"| {f['makespan_cycles'] / 1e6:.2f} | {f['parallel_efficiency']:.3f} "
            f"| {rays.cells(f['work_per_ray'])} | {rays.cells(f['fanout_mean'], '{:.2f}')} "
            f"| {rays.cells(f['bus_bytes_per_ray'])} | {f['gpp_starved_cycles'] / 1e6:.2f} "
            f"| {rays.cells(f['spawn_delay_cycles_mean'], '{:,.0f}')} |")


def at_check(base, args, f, out, oprt):
    """The same run at --level at: the figures both levels print, and whether the makespan,
    busy cycles and image agree (the script ends if not)."""
    a = figures(render(args[:-1] + ["at"], out, oprt, WHO))
    same = all(a[k] == f[k] for k in ("makespan_cycles", "busy_cycles", "image_hash"))
    print(f"{base}: makespan {f['makespan_cycles']:,} analytic, {a['makespan_cycles']:,} at; busy "
          f"{f['busy_cycles']:,} / {a['busy_cycles']:,}; image {f['image_hash']} / {a['image_hash']}; "
          f"GPP starved {f['gpp_starved_cycles']:,} / {a['gpp_starved_cycles']:,}; spawn delay "
          f"{rays.cells(f['spawn_delay_cycles_mean'])} / {rays.cells(a['spawn_delay_cycles_mean'])}: "
          + ("same" if same else "DIFFERENT"), flush=True)
    if not same:
        sys.exit(f"{WHO}: {base}: the at level's makespan, busy cycles or image differ from the analytic level's")


def plot(rows, depths, path):
    """Efficiency and makespan against depth, a line per route, a row of two panels per scene."""
    from .. import plots
    plt = plots.pyplot("plots")
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(len(scenes), 2, figsize=(9, 3.2 * len(scenes)), squeeze=False)
    for (ax_e, ax_m), scene in zip(axes, scenes):
        for route, marker in zip(ROUTES, "so^"):
            mine = sorted((r for r in rows if r["scene"] == scene and r["route"] == route), key=lambda r: r["depth"])
            xs = [r["depth"] for r in mine]
            ax_e.plot(xs, [r["parallel_efficiency"] for r in mine], marker=marker, label=route)
            ax_m.plot(xs, [r["makespan_cycles"] / 1e6 for r in mine], marker=marker, label=route)
        first = next(r for r in rows if r["scene"] == scene)
        for ax, what in ((ax_e, "parallel efficiency"), (ax_m, "makespan (M cycles)")):
            ax.set_title(f"{scene}, {first['resolution']}, frame 0: {what}", fontsize=9)
            ax.set_xlabel("depth (bounces of reflection and refraction)")
            ax.set_ylabel(what)
            ax.set_xticks(list(depths))
            ax.set_ylim(bottom=0)
            ax.grid(alpha=0.3)
        ax_e.legend(fontsize=8)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    plots.atomic_savefig(fig, path)
    print(path)


def pictures(scenes, depths, resolution, out, folder, oprt):
    """Each scene's frame 0 by `oprt reference` at the first and the last depth, side by side
    (a 4-pixel white gap) in folder/SCENE_depthA_depthB.png; prints each run's rays."""
    from .. import plots
    plots.require("plots", "PIL")
    from PIL import Image
    os.makedirs(folder, exist_ok=True)
    for name, path in scenes:
        images = []
        for depth in (depths[0], depths[-1]):
            run_out = os.path.join(out, "pictures", name, f"depth{depth}")
            ref = reference([path, "--frames", "0", "--resolution", resolution, "--depth", depth], run_out, oprt, WHO)
            print(f"{name} depth {depth}: reference rays {rays.cells(rays.rays(ref['frames'][0]))} ({rays.LETTERS})")
            images.append(Image.open(os.path.join(run_out, "frame_0000.png")).convert("RGB"))
        w, h = images[0].size
        both = Image.new("RGB", (2 * w + 4, h), "white")
        both.paste(images[0], (0, 0))
        both.paste(images[1], (w + 4, 0))
        target = os.path.join(folder, f"{name}_depth{depths[0]}_depth{depths[-1]}.png")
        both.save(target + ".tmp.png", optimize=True)
        os.replace(target + ".tmp.png", target)
        print(f"{target}: {os.path.getsize(target):,} bytes")


def main(argv=None):
    ap = script_arguments(__doc__, WHO)
    ap.add_argument("--scenes", default="kitchen,museum")
    ap.add_argument("--depths", default="0:5", help="A:B, inclusive")
    ap.add_argument("--resolution", default="128x96")
    ap.add_argument("--balance", default="spatial")
    ap.add_argument("--arch", default=os.path.join(paths.ARCH, "paper.json"))
    ap.add_argument("--level", default="analytic", choices=("analytic", "at"))
    ap.add_argument("--json", help="write every row's figures here as well")
    ap.add_argument("--plot", help="efficiency and makespan against depth (PNG)")
    ap.add_argument("--pictures", help="folder for the side-by-side reference pictures")
    ap.add_argument("--picture-resolution", default="320x240")
    a = ap.parse_args(argv)
    first, last = (int(v) for v in a.depths.split(":"))
    depths = range(first, last + 1)
    wanted = chosen_scenes(a.scenes, [name for name, _ in SCENES], WHO)
    scenes = list(scenes_present([s for s in SCENES if s[0] in wanted], WHO))
    print("| scene | depth | route | rays (P / S / R / T) | rays / pixel | busy per unit, mean / max (M cycles) "
          "| makespan (M cycles) | efficiency | work per ray (cycles, P / S / R / T) | fan-out (P / S / R / T) "
          "| bus bytes per ray (P / S / R / T) | GPP starved (M cycles) | spawn delay (cycles, P / S / R / T) |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    rows, checks = [], []
    for name, path in scenes:
        for depth in depths:
            hashes = None
            for route in ROUTES:
                args = [path, "--arch", a.arch, "--ius", "32", "--accel", "bvh", "--top", "bvh", "--balance", a.balance,
                        "--route", route, "--depth", depth, "--frames", "0", "--resolution", a.resolution,
                        "--level", a.level]
                f = figures(render(args, os.path.join(a.out, name, f"depth{depth}", route), a.oprt, WHO))
                if hashes is None:
                    hashes = (f["image_hash"], f["rays"])
                elif (f["image_hash"], f["rays"]) != hashes:
                    sys.exit(f"{WHO}: {name} depth {depth} {route}: the image or the rays differ from broadcast's")
                f.update(scene=name, depth=depth, route=route, resolution=a.resolution, balance=a.balance)
                rows.append(f)
                print(row(name, depth, route, f), flush=True)
                if depth == last and a.level == "analytic":
                    checks.append((f"{name} depth {depth} {route}", args, f,
                                   os.path.join(a.out, name, f"depth{depth}", route + "_at")))
    for base, args, f, out in checks:
        at_check(base, args, f, out, a.oprt)
    if a.json:
        with open(a.json, "w") as fp:
            json.dump(rows, fp, indent=1)
    if a.plot:
        plot(rows, depths, a.plot)
    if a.pictures:
        pictures(scenes, list(depths), a.picture_resolution, a.out, a.pictures, a.oprt)

