"""Each timing level's error against `at` for every combination of unit model, acceleration,
tree over a unit's spheres and object memory, under contention (docs/timing-levels.md): for
each combination it runs

  oprt render SCENE --arch testbench/arch/contended.json --frames F --resolution R
       --subdivide 2 --ius 16 --balance sa_n --iu IU --accel A --top T [--sram S] --level L

at `at`, `lt` (quantum 1 us) and `analytic`, and prints one markdown row: at's makespan, each
level's relative makespan error and wall time, and whether the units' work cycles and the images
agree (they must: the work is the functional trace's at every level). The contended architecture: ray FIFOs
of 4, a shared bus of 8 bytes per cycle, on-chip memory with a latency of 10 cycles.

  scripts/level_errors [--out DIR] [--oprt PATH] [--scene PATH] [--frames F] [--resolution WxH]
"""
import os

from .. import paths
from ..render import render, script_arguments


def work(frame):
    """Every unit's work cycles by activity (a pipelined unit's: its units' issue slots), which no
    level may change; a pipelined unit's busy_cycles (the time it held rays) is timing."""
    return [[u["cycles"][k] for k in ("sphere", "transform", "box", "primitive", "node")] for u in frame["ius"]]


def main(argv=None):
    ap = script_arguments(__doc__, "level_errors", scene=os.path.join(paths.SCENES, "paper_room.json"), frames="0",
                          resolution="128x128")
    a = ap.parse_args(argv)
    arch = os.path.join(paths.ARCH, "contended.json")
    print("| IU | accel | top | memory | at makespan | lt error | analytic error | at s | lt s | analytic s | busy and image |")
    print("|---|---|---|---|---:|---:|---:|---:|---:|---:|---|")
    worst = 0.0
    for iu in ("serial", "pipelined"):
        for accel in ("brute", "bvh"):
            for top in ("flat", "bvh"):
                for sram in ("on-chip", "16K"):
                    base = [a.scene, "--arch", arch, "--frames", a.frames, "--resolution", a.resolution, "--subdivide",
                            "2", "--ius", "16", "--balance", "sa_n", "--iu", iu, "--accel", accel, "--top", top]
                    if sram != "on-chip":
                        base += ["--sram", sram]
                    res = {}
                    for level in ("at", "lt", "analytic"):
                        stats, wall = render(base + ["--level", level], os.path.join(a.out, f"{iu}_{accel}_{top}_{sram}_{level}"),
                                             a.oprt, "level_errors", timed=True)
                        res[level] = stats["frames"][0], wall
                    at = res["at"][0]
                    errors = {}
                    same = True
                    for level in ("lt", "analytic"):
                        f = res[level][0]
                        errors[level] = (f["makespan_cycles"] - at["makespan_cycles"]) / at["makespan_cycles"]
                        worst = max(worst, abs(errors[level]))
                        same = same and work(f) == work(at) and f["image_hash"] == at["image_hash"]
                    print(f"| {iu} | {accel} | {top} | {sram} | {at['makespan_cycles']:,} | {100 * errors['lt']:+.3f}% | "
                          f"{100 * errors['analytic']:+.3f}% | {res['at'][1]:.2f} | {res['lt'][1]:.2f} | "
                          f"{res['analytic'][1]:.2f} | {'same' if same else 'DIFFERENT'} |", flush=True)
    print(f"\nworst |error|: {100 * worst:.3f}%")
    return 0

