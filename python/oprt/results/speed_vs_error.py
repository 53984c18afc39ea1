"""Speed against error: what each level of detail, precision and kernel costs and gets wrong.

  scripts/speed_vs_error [SCENE...] [--frames F] [--resolution WxH] [--quanta LIST] [--out DIR]
                         [--ius N] [--iu serial|pipelined] [--no-variants] [--no-images] [--oprt PATH]

SCENE defaults to both paper scenes; frame 0 at 256x256 (the paper's) takes about 3.5 minutes
for both on the project's 2-core machine, --resolution 64x64 about 20 s. For each scene it
runs, one process at a time (wall times must not compete with each other):

Timing table, under two architectures: `ideal` (testbench/arch/paper.json, the paper's
assumptions) and `contended` (the same with ray FIFOs of depth 4, a shared bus at 8 bytes per
cycle and object memory latency of 10 cycles):
  at                 the timing reference
  lt, each quantum   temporal decoupling (default quanta 10 ns to 100 us); on the shared bus the
                     initiators synchronise before each transfer (bus.lt_arbitration = sync)
  analytic           no SystemC: a recurrence over the functional traversal
  lt calendar, lt busy_until, each quantum (contended only; --no-variants skips them): lt with
                     the other two bus.lt_arbitration methods: requests up to a quantum ahead
                     slotted into the bus's calendar of grants, and the naive "busy until"
                     arbiter (model/hw/bus.h)
Columns: wall seconds of the whole `oprt render` process and its CPU seconds (user + system:
less disturbed than wall time when other work shares the machine); simulated rays per wall second;
makespan and its error against `at` of the same architecture; per-IU idle error against `at`,
as L1 (sum over units of |idle - idle_at| / sum of idle_at) and max (largest |idle - idle_at|
of one unit / makespan_at). Images and busy cycles are identical at every level (tested), so
the error is timing only. --iu pipelined measures the same for pipelined intersection units
(their stages' issue cycles are the busy cycles compared).

Image table (--no-images skips it): `oprt render --level lt` under the ideal architecture for
each precision (float, double) and kernel (moller; watertight too when `oprt render --kernel
watertight` works in this build), against the double-precision functional reference
`oprt reference --precision double`: wall seconds, rays per second, makespan, pixels whose
objectId or primId differ, colour RMSE and max relative Z error (`oprt compare`).

Writes OUT/speed_vs_error.md (both tables, as printed), OUT/timing.csv, OUT/images.csv and
OUT/speed_vs_error.png (error against wall time per scene). Default OUT: out/speed_vs_error.
With several frames (--frames A:B) makespans and idle cycles are summed over the frames and
image errors are the worst frame's (id mismatches summed).
Exit status: 0 done, 1 a run failed, 2 bad command line.
"""
import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker

from .. import paths
from ..stats import frame_rays
PAPER_ARCH = os.path.join(paths.ARCH, "paper.json")
DEFAULT_SCENES = [os.path.join(paths.SCENES, s) for s in ("paper_room.json", "paper_polygons.json")]
DEFAULT_QUANTA = "10ns,100ns,1us,10us,100us"
CONTENDED = {"ray_fifo_depth": 4, "bus": {"model": "shared", "bytes_per_cycle": 8},
             "memory": {"model": "latency", "latency_cycles": 10}}


class RunFailed(Exception):
    pass


def run(cmd, times=None):
    """Runs cmd; returns (wall seconds, stdout) and, into times, wall and CPU (user + system)
    seconds. Raises RunFailed with its output on failure."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode:
        raise RunFailed(f"{' '.join(cmd)}\nexit {r.returncode}: {r.stdout}{r.stderr}".rstrip())
    if times is not None:
        times["wall_s"] = wall
        times["cpu_s"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, r.stdout


def write_arch(path, extra):
    with open(PAPER_ARCH) as f:
        arch = json.load(f)
    arch.pop("comment", None)
    for k, v in extra.items():
        arch[k] = {**arch.get(k, {}), **v} if isinstance(v, dict) else v
    with open(path, "w") as f:
        json.dump(arch, f, indent=1)
    return path


def stats(out_dir):
    with open(os.path.join(out_dir, "stats.json")) as f:
        return json.load(f)["frames"]


def summarise(frames):
    """Makespan, rays, per-unit idle, summed over the frames."""
    units = len(frames[0]["ius"])
    return {"makespan": sum(f["makespan_cycles"] for f in frames),
            "rays": sum(frame_rays(f) for f in frames),
            "idle": [sum(f["ius"][u]["cycles"]["idle"] for f in frames) for u in range(units)],
            "busy": [[f["ius"][u]["cycles"][k] for k in ("sphere", "transform", "primitive")]
                     for f in frames for u in range(units)]}


def render(args, scene, arch, out_dir, *flags):
    cmd = [args.oprt, "render", scene, "--arch", arch, "--frames", args.frames, "--out", out_dir,
           "--no-progress", *flags]
    if args.resolution:
        cmd += ["--resolution", args.resolution]
    if args.ius:
        cmd += ["--ius", str(args.ius)]
    if args.iu:
        cmd += ["--iu", args.iu]
    times = {}
    run(cmd, times)
    return times, summarise(stats(out_dir)), cmd


def timing_rows(args, scene, name, work):
    """The timing table's rows for one scene."""
    archs = {"ideal": write_arch(os.path.join(work, "arch_ideal.json"), {}),
             "contended": write_arch(os.path.join(work, "arch_contended.json"), CONTENDED)}
    variants = {v: write_arch(os.path.join(work, f"arch_contended_{v}.json"),
                              {**CONTENDED, "bus": {**CONTENDED["bus"], "lt_arbitration": v}})
                for v in ("calendar", "busy_until")}
    rows = []
    for arch_name, arch in archs.items():
        runs = [("at", "", arch, ["--level", "at"])]
        runs += [("lt", q, arch, ["--level", "lt", "--quantum", q]) for q in args.quanta]
        runs += [("analytic", "", arch, ["--level", "analytic"])]
        if arch_name == "contended" and not args.no_variants:
            for v, file in variants.items():
                runs += [(f"lt {v}", q, file, ["--level", "lt", "--quantum", q]) for q in args.quanta]
        ref = None
        for level, quantum, arch_file, flags in runs:
            tag = f"{name}-{arch_name}-{level.replace(' ', '_')}{quantum}"
            progress(f"{name} {arch_name} {level} {quantum}")
            t, s, cmd = render(args, scene, arch_file, os.path.join(work, tag), *flags)
            if ref is None:
                ref = s  # `at` comes first
            if s["busy"] != ref["busy"]:
                raise RunFailed(f"{' '.join(cmd)}: busy cycles differ from at (a model bug: they must be identical)")
            idle_at = sum(ref["idle"])
            delta = [abs(a - b) for a, b in zip(s["idle"], ref["idle"])]
            rows.append({"scene": name, "arch": arch_name, "level": level, "quantum": quantum,
                         "wall_s": t["wall_s"], "cpu_s": t["cpu_s"], "rays": s["rays"],
                         "rays_per_s": s["rays"] / t["wall_s"],
                         "makespan": s["makespan"],
                         "makespan_err_pct": 100 * (s["makespan"] - ref["makespan"]) / ref["makespan"],
                         "idle_err_l1_pct": 100 * sum(delta) / idle_at if idle_at else 0.0,
                         "idle_err_max_pct": 100 * max(delta) / ref["makespan"],
                         "command": " ".join(cmd)})
    return rows


def watertight_available(args, scene, work):
    """Whether this build renders with --kernel watertight (it may not exist yet)."""
    try:
        run([args.oprt, "render", scene, "--kernel", "watertight", "--level", "analytic", "--frames",
             args.frames.split(":")[0], "--resolution", "8x8", "--no-progress", "--out",
             os.path.join(work, "watertight-probe")])
        return True, ""
    except RunFailed as e:
        return False, str(e).splitlines()[-1]


def frame_files(out_dir):
    return sorted(f for f in os.listdir(out_dir) if f.startswith("frame_") and f.endswith(".exr"))


def image_rows(args, scene, name, work, kernels):
    ref_dir = os.path.join(work, f"{name}-reference-double")
    cmd = [args.oprt, "reference", scene, "--precision", "double", "--frames", args.frames, "--out", ref_dir]
    if args.resolution:
        cmd += ["--resolution", args.resolution]
    progress(f"{name} reference double")
    ref_wall, _ = run(cmd)
    rows = []
    arch = os.path.join(work, "arch_ideal.json")
    for kernel in kernels:
        for precision in ("float", "double"):
            progress(f"{name} images {kernel} {precision}")
            out = os.path.join(work, f"{name}-image-{kernel}-{precision}")
            t, s, rcmd = render(args, scene, arch, out, "--level", "lt", "--kernel", kernel, "--precision", precision)
            diffs = []
            for f in frame_files(out):
                _, text = run([args.oprt, "compare", os.path.join(out, f), os.path.join(ref_dir, f)])
                diffs.append(json.loads(text))
            rows.append({"scene": name, "kernel": kernel, "precision": precision, "wall_s": t["wall_s"],
                         "cpu_s": t["cpu_s"], "rays_per_s": s["rays"] / t["wall_s"], "makespan": s["makespan"],
                         "id_mismatches": sum(d["id_mismatches"] for d in diffs),
                         "pixels": sum(d["pixels"] for d in diffs),
                         "color_rmse": max(d["color_rmse"] for d in diffs),
                         "max_rel_z": max(d["max_rel_z"] for d in diffs),
                         "reference_wall_s": ref_wall, "command": " ".join(rcmd)})
    return rows


def progress(text):
    if sys.stderr.isatty():
        sys.stderr.write(f"\r\033[Kspeed_vs_error: {text}")
        sys.stderr.flush()


def timing_table(rows):
    out = ["| scene | arch | level | quantum | wall s | cpu s | rays/s | makespan (cycles) | makespan err | idle err L1 | idle err max |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scene']} | {r['arch']} | {r['level']} | {r['quantum'] or '-'} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
                   f"{r['rays_per_s'] / 1e3:.1f} k | {r['makespan']:,} | {r['makespan_err_pct']:+.3f}% | "
                   f"{r['idle_err_l1_pct']:.3f}% | {r['idle_err_max_pct']:.3f}% |")
    return "\n".join(out)


def image_table(rows):
    out = ["| scene | kernel | precision | wall s | cpu s | rays/s | makespan (cycles) | id mismatches | colour RMSE | max rel Z err |",
           "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['scene']} | {r['kernel']} | {r['precision']} | {r['wall_s']:.2f} | {r['cpu_s']:.2f} | "
                   f"{r['rays_per_s'] / 1e3:.1f} k | {r['makespan']:,} | {r['id_mismatches']} of {r['pixels']} | "
                   f"{r['color_rmse']:.2e} | {r['max_rel_z']:.2e} |")
    return "\n".join(out)


def write_csv(path, rows):
    if not rows:
        return
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def plot(rows, path):
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(2, len(scenes), figsize=(6.5 * len(scenes), 8), squeeze=False, constrained_layout=True)
    styles = {("ideal", "lt"): dict(color="#4c72b0", marker="o", linestyle="-"),
              ("contended", "lt"): dict(color="#c44e52", marker="o", linestyle="-"),
              ("contended", "lt calendar"): dict(color="#dd8452", marker="D", linestyle="-."),
              ("contended", "lt busy_until"): dict(color="#8c8c8c", marker="x", linestyle="--")}
    for col, scene in enumerate(scenes):
        for row, (key, label) in enumerate((("makespan_err_pct", "makespan error against at (%)"),
                                            ("idle_err_l1_pct", "per-IU idle error against at, L1 (%)"))):
            ax = axes[row][col]
            for (arch, level), style in styles.items():
                pts = [r for r in rows if r["scene"] == scene and r["arch"] == arch and r["level"] == level]
                if not pts:
                    continue
                ax.plot([p["wall_s"] for p in pts], [p[key] for p in pts], label=f"{arch}: {level}", **style)
                for p in pts:
                    ax.annotate(p["quantum"], (p["wall_s"], p[key]), textcoords="offset points", xytext=(4, 4),
                                fontsize=7, color=style["color"])
            for arch, colour in (("ideal", "#4c72b0"), ("contended", "#c44e52")):
                for level, marker in (("at", "s"), ("analytic", "^")):
                    for p in (r for r in rows if r["scene"] == scene and r["arch"] == arch and r["level"] == level):
                        ax.plot(p["wall_s"], p[key], marker=marker, color=colour, linestyle="none", markersize=8,
                                markerfacecolor="white", label=f"{arch}: {level}")
            ax.axhline(0, color="grey", linewidth=0.8)
            ax.set_xscale("log")
            ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax.xaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
            ax.set_xlabel("wall seconds (whole oprt render process)")
            ax.set_ylabel(label)
            ax.set_title(scene)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="*", metavar="SCENE", help="scene files (default: both paper scenes)")
    p.add_argument("--frames", default="0", help="N or A:B (default 0)")
    p.add_argument("--resolution", default="256x256", help="WxH (default 256x256, the paper's; '' = the scene's)")
    p.add_argument("--quanta", default=DEFAULT_QUANTA, help=f"lt quanta, comma-separated (default {DEFAULT_QUANTA})")
    p.add_argument("--ius", type=int, help="intersection units (default: the architecture's, 32)")
    p.add_argument("--iu", choices=("serial", "pipelined"), help="the intersection unit's model (default: serial)")
    p.add_argument("--out", default=os.path.join("out", "speed_vs_error"), help="output directory")
    p.add_argument("--no-variants", action="store_true",
                   help="skip the lt runs with the calendar and busy_until bus arbitration")
    p.add_argument("--no-images", action="store_true", help="skip the precision and kernel table")
    p.add_argument("--oprt", default=paths.oprt_binary(),
                   help="the oprt binary (default build/testbench/oprt)")
    args = p.parse_args(argv)
    args.quanta = [q.strip() for q in args.quanta.split(",") if q.strip()]
    if not args.quanta:
        p.error("--quanta: no quantum given")
    if not os.access(args.oprt, os.X_OK):
        p.error(f"--oprt: {args.oprt} is not an executable (run scripts/build)")
    scenes = args.scenes or DEFAULT_SCENES
    for s in scenes:
        if not os.path.isfile(s):
            p.error(f"{s}: no such scene file")
    work = os.path.join(args.out, "runs")
    os.makedirs(work, exist_ok=True)

    t0 = time.perf_counter()
    timing, images, notes = [], [], []
    try:
        kernels = ["moller"]
        if not args.no_images:
            ok, why = watertight_available(args, scenes[0], work)
            if ok:
                kernels.append("watertight")
            else:
                notes.append(f"watertight kernel not available in this build ({why}): moller only.")
        for scene in scenes:
            name = os.path.splitext(os.path.basename(scene))[0]
            timing += timing_rows(args, scene, name, work)
            if not args.no_images:
                images += image_rows(args, scene, name, work, kernels)
    except RunFailed as e:
        progress("")
        sys.exit(f"speed_vs_error: a run failed:\n{e}")
    progress("")
    sys.stderr.write("\r\033[K" if sys.stderr.isatty() else "")

    res = args.resolution or "the scene's resolution"
    ius = args.ius or "the architecture's"
    head = (f"frames {args.frames}, {res}, {ius} {args.iu or 'serial'} IUs; "
            f"one process at a time; total {time.perf_counter() - t0:.0f} s.")
    text = [f"Speed against error ({head})", "", timing_table(timing)]
    if images:
        text += ["", "Image error against `oprt reference --precision double` (render --level lt, ideal architecture):",
                 "", image_table(images)]
    text += [""] + notes if notes else []
    report = "\n".join(text) + "\n"
    print(report, end="")
    with open(os.path.join(args.out, "speed_vs_error.md"), "w") as f:
        f.write(report)
    write_csv(os.path.join(args.out, "timing.csv"), timing)
    write_csv(os.path.join(args.out, "images.csv"), images)
    plot(timing, os.path.join(args.out, "speed_vs_error.png"))
    print(f"wrote {os.path.join(args.out, 'speed_vs_error.md')}, timing.csv, images.csv and speed_vs_error.png")

