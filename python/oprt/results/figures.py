"""The paper's load-balancing figures, reproduced with the timed model, and ours beside them.

  scripts/figures [--out docs/plots] [--frames 30]

256x256, 32 IUs, testbench/arch/paper.json (the paper's ideal architecture).
Fig. 7: per-IU cycles (sphere, transform, primitive, idle), both paper scenes, `paper` policy.
Fig. 8: per-IU primitive-test cycles against the SA x N of the IU's sphere, with Pearson r;
        and, for the room split into 8 per object, each sphere's cycles against its SA x N
        and against the sa_n cost estimate (model/balance/policy.h).
Fig. 10: the room with --subdivide 8 --balance sa_n; then feedback and view; and the
        efficiency of every policy frame by frame.
The plots show frame 0 at --level at (feedback: frame 1, its first re-balanced frame). The
tables cover frames 0:FRAMES-1 at --level analytic, which equals at exactly under this
architecture (tests/cli/cli_test.cpp; checked again here on frame 0). Speedup over 1 IU:
the same spheres and frames on one unit, total makespan over total makespan.
"""
import argparse
import json
import os
import sys
import tempfile

from .. import paths, plots, render as oprt_render
from ..stats import pearson
plt = plots.pyplot("plots")

OPRT = paths.oprt_binary()
ARCH = os.path.join(paths.ARCH, "paper.json")
COLORS = {"sphere": "#4c72b0", "transform": "#dd8452", "primitive": "#55a868", "idle": "#c8c8c8", "stall": "#c44e52"}
K8 = ["--subdivide", "8"]

# name -> (scene, flags, 1-IU reference name); the 30-frame runs behind the tables.
POLICIES = {
    "room, paper": ("paper_room", [], "room, 1 IU"),
    "room, round_robin, subdivide 8": ("paper_room", K8 + ["--balance", "round_robin"], "room, 1 IU, subdivide 8"),
    "room, sa_n, subdivide 8": ("paper_room", K8 + ["--balance", "sa_n"], "room, 1 IU, subdivide 8"),
    "room, sa_n, subdivide 8, median split": ("paper_room", K8 + ["--balance", "sa_n", "@median"],
                                              "room, 1 IU, subdivide 8, median split"),
    "room, feedback, subdivide 8": ("paper_room", K8 + ["--balance", "feedback"], "room, 1 IU, subdivide 8"),
    "room, view, subdivide 8": ("paper_room", K8 + ["--balance", "view"], "room, 1 IU, subdivide 8"),
    "polygons, paper": ("paper_polygons", [], "polygons, 1 IU"),
    "polygons, sa_n, subdivide 8": ("paper_polygons", K8 + ["--balance", "sa_n"], "polygons, 1 IU, subdivide 8"),
    "polygons, feedback, subdivide 8": ("paper_polygons", K8 + ["--balance", "feedback"], "polygons, 1 IU, subdivide 8"),
}
ONE_IU = {
    "room, 1 IU": ("paper_room", ["--ius", "1"]),
    "room, 1 IU, subdivide 8": ("paper_room", K8 + ["--ius", "1"]),
    "room, 1 IU, subdivide 8, median split": ("paper_room", K8 + ["--ius", "1", "@median"]),
    "polygons, 1 IU": ("paper_polygons", ["--ius", "1"]),
    "polygons, 1 IU, subdivide 8": ("paper_polygons", K8 + ["--ius", "1"]),
}


def arch_file(tmp, flags):
    """The paper's architecture, or a variant: '@median' selects the median split rule,
    '@shared' a shared bus of 8 bytes per cycle."""
    variant = [f for f in flags if f.startswith("@")]
    if not variant:
        return ARCH
    with open(ARCH) as f:
        arch = json.load(f)
    if "@median" in variant:
        arch["split_rule"] = "median"
    if "@shared" in variant:
        arch["bus"] = {"model": "shared", "bytes_per_cycle": 8, "arbitration_cycles": 1}
    path = os.path.join(tmp, "arch_" + "_".join(v[1:] for v in variant) + ".json")
    with open(path, "w") as f:
        json.dump(arch, f)
    return path


def render(scene, tmp, tag, *flags):
    out = os.path.join(tmp, tag.replace(" ", "_").replace(",", ""))
    args = [os.path.join(paths.SCENES, scene + ".json"), "--arch", arch_file(tmp, flags),
            *[f for f in flags if not f.startswith("@")]]
    cmd = oprt_render.command(args, out, OPRT)
    print("  " + " ".join(os.path.relpath(c, paths.REPO) if c.startswith(paths.REPO) else c for c in cmd), file=sys.stderr)
    return oprt_render.render(args, out, OPRT, "figures")


def stacked(ax, frame, title):
    units = frame["ius"]
    x = range(len(units))
    bottom = [0] * len(units)
    for k in ("sphere", "transform", "primitive", "idle"):
        h = [u["cycles"][k] / 1e6 for u in units]
        ax.bar(x, h, bottom=bottom, color=COLORS[k], label=k, width=0.85)
        bottom = [b + v for b, v in zip(bottom, h)]
    ax.set_title(f"{title}\nmakespan {frame['makespan_cycles'] / 1e6:.1f} M cycles, "
                 f"efficiency {frame['parallel_efficiency']:.3f}", fontsize=9)
    ax.set_xlabel("intersection unit")
    ax.set_ylabel("M cycles")


def unit_san(stats, frame):
    sa_n = [s["sa_n"] for s in stats["sphere_list"]]
    return [sum(sa_n[i] for i in u["spheres"]) for u in frame["ius"]]


def summary(st, one):
    fr = st["frames"]
    n = len(fr)
    ms = sum(f["makespan_cycles"] for f in fr)
    eff = [f["parallel_efficiency"] for f in fr]
    one_ms = sum(f["makespan_cycles"] for f in one["frames"])
    return {
        "makespan": ms / n, "eff": sum(eff) / n, "eff_min": min(eff), "eff_max": max(eff),
        "idle": sum(f["idle_fraction"] for f in fr) / n, "speedup": one_ms / ms,
        "moved": sum(f["memory_load_bytes"] for f in fr) / n, "moved_cycles": sum(f["memory_load_cycles"] for f in fr) / n,
        "busy": sum(f["busy_cycles"] for f in fr) / n,
    }


def draw(out, shown, runs):
    """Figs. 7, 8 and 10 into `out`; returns the Pearson r of Fig. 8 by panel."""
    # Fig. 7
    fig, axes = plt.subplots(1, 2, figsize=(12, 4))
    stacked(axes[0], shown["polygons, paper"]["frames"][0], "(a) polygons, paper policy")
    stacked(axes[1], shown["room, paper"]["frames"][0], "(b) room, paper policy")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig7_per_iu_cycles.png"), dpi=110)

    # Fig. 8
    fig, axes = plt.subplots(1, 4, figsize=(21, 4.2))
    rs = {}
    for ax, key, title in ((axes[0], "polygons, paper", "(a) polygons, per IU"),
                           (axes[1], "room, paper", "(b) room, per IU")):
        st = shown[key]
        f = st["frames"][0]
        xs = unit_san(st, f)
        ys = [u["cycles"]["primitive"] / 1e6 for u in f["ius"]]
        rs[key] = pearson(xs, ys)
        ax.scatter(xs, ys, s=18, color=COLORS["primitive"])
        ax.set_title(f"{title}: Pearson r = {rs[key]:.3f}", fontsize=10)
        ax.set_xlabel("SA x N of the IU's sphere")
        ax.set_ylabel("primitive-test M cycles")
    st = shown["room, sa_n, subdivide 8"]
    cyc = [c / 1e6 for c in st["frames"][0]["sphere_cycles"]]
    for ax, key, label, title in ((axes[2], "sa_n", "SA x N of the sphere", "(c) room, subdivide 8, per sphere"),
                                  (axes[3], "sa_n_weight", "sa_n estimate (cycles per primary ray)",
                                   "(d) room, subdivide 8, per sphere")):
        xs = [s[key] for s in st["sphere_list"]]
        rs["room8 " + key] = pearson(xs, cyc)
        ax.scatter(xs, cyc, s=10, color=COLORS["sphere"])
        ax.set_title(f"{title}: Pearson r = {rs['room8 ' + key]:.3f}", fontsize=10)
        ax.set_xlabel(label)
        ax.set_ylabel("busy M cycles")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig8_primitive_vs_san.png"), dpi=110)

    # Fig. 10 and beyond
    order = ["room, paper", "room, sa_n, subdivide 8", "room, feedback, subdivide 8", "room, view, subdivide 8"]
    fig, axes = plt.subplots(1, 4, figsize=(20, 4), sharey=True)
    for ax, key in zip(axes, order):
        stacked(ax, shown[key]["frames"][0], key + (" (frame 1)" if "feedback" in key else ""))
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig10_room_balanced.png"), dpi=110)

    fig, ax = plt.subplots(figsize=(8, 4))
    for name, st in runs.items():
        if name.startswith("room"):
            ax.plot([f["frame"] for f in st["frames"]], [f["parallel_efficiency"] for f in st["frames"]],
                    marker=".", label=name[6:])
    ax.set_xlabel("frame")
    ax.set_ylabel("parallel efficiency")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title("room, 32 IUs, 256x256: efficiency per frame", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "fig10_efficiency_per_frame.png"), dpi=110)
    return rs


def tables(frames, shown, runs, one, shared, shared_san, rs):
    """The markdown tables of docs/results.md behind the figures."""
    def one_frame(st, f):  # the 1-IU run's frame with the same number
        return next(x for x in st["frames"] if x["frame"] == f)

    print("\nThe plotted frames (frame 0; feedback frame 1), --level at:\n")
    print("| scene, policy | makespan (cycles) | parallel efficiency | idle fraction | speedup over 1 IU |")
    print("|---|---|---|---|---|")
    for name in ("polygons, paper", "room, paper", "room, sa_n, subdivide 8", "room, feedback, subdivide 8",
                 "room, view, subdivide 8"):
        f = shown[name]["frames"][0]
        o = one_frame(one[POLICIES[name][2]], f["frame"])
        print(f"| {name} | {f['makespan_cycles']:,} | {f['parallel_efficiency']:.3f} | {f['idle_fraction']:.3f} | "
              f"{o['makespan_cycles'] / f['makespan_cycles']:.2f} |")
    print(f"\nFig. 8 Pearson r, per-IU primitive cycles vs SA x N: polygons {rs['polygons, paper']:.3f}, "
          f"room {rs['room, paper']:.3f}; room subdivided by 8, per-sphere busy cycles vs SA x N "
          f"{rs['room8 sa_n']:.3f}, vs the sa_n estimate {rs['room8 sa_n_weight']:.3f}")

    print(f"\nFrames {frames}, --level analytic (= at under these assumptions):\n")
    print("| scene, policy | mean makespan (M cycles) | parallel efficiency: mean (min-max) | idle fraction | "
          "speedup over 1 IU | busy (M cycles) | geometry moved per frame |")
    print("|---|---|---|---|---|---|---|")
    for name, (scene, flags, ref) in POLICIES.items():
        s = summary(runs[name], one[ref])
        print(f"| {name} | {s['makespan'] / 1e6:.2f} | {s['eff']:.3f} ({s['eff_min']:.3f}-{s['eff_max']:.3f}) | "
              f"{s['idle']:.3f} | {s['speedup']:.2f} | {s['busy'] / 1e6:.0f} | {s['moved'] / 1e3:.0f} kB |")
    for name, st in (("sa_n", shared_san), ("feedback", shared)):
        s = summary(st, one["room, 1 IU, subdivide 8"])
        print(f"\nShared bus (8 B/cycle, 1 arbitration cycle), room, {name}, subdivide 8, frames {frames}: "
              f"mean makespan {s['makespan'] / 1e6:.2f} M cycles, efficiency {s['eff']:.3f}, "
              f"geometry moved {s['moved'] / 1e3:.0f} kB and {s['moved_cycles']:,.0f} bus cycles per frame "
              f"({s['moved_cycles'] / s['makespan'] * 100:.2f} % of the makespan)")

    print("\nSplit rules, room, subdivide 8:\n")
    print("| split rule | spheres | sum of SA x N | busy, frame 0 (M cycles) | sa_n: mean efficiency | "
          "sa_n: mean makespan (M cycles) |")
    print("|---|---|---|---|---|---|")
    for rule, name in (("balanced", "room, sa_n, subdivide 8"), ("median", "room, sa_n, subdivide 8, median split")):
        st = runs[name]
        s = summary(st, one[POLICIES[name][2]])
        print(f"| {rule} | {len(st['sphere_list'])} | {sum(x['sa_n'] for x in st['sphere_list']):,.0f} | "
              f"{st['frames'][0]['busy_cycles'] / 1e6:.0f} | {s['eff']:.3f} | {s['makespan'] / 1e6:.2f} |")
    st = runs["room, paper"]
    print(f"| (no subdivision) | {len(st['sphere_list'])} | {sum(x['sa_n'] for x in st['sphere_list']):,.0f} | "
          f"{st['frames'][0]['busy_cycles'] / 1e6:.0f} | | |")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default=os.path.join(paths.REPO, "docs", "plots"))
    p.add_argument("--frames", type=int, default=30)
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    frames = f"0:{a.frames - 1}"
    with tempfile.TemporaryDirectory(prefix="oprt_figures_") as tmp:
        # Frame 0 at the timing reference level, for the plots.
        at = ["--level", "at", "--frames", "0"]
        shown = {
            "polygons, paper": render("paper_polygons", tmp, "at poly", *at),
            "room, paper": render("paper_room", tmp, "at room", *at),
            "room, sa_n, subdivide 8": render("paper_room", tmp, "at room san8", *at, *K8, "--balance", "sa_n"),
            "room, view, subdivide 8": render("paper_room", tmp, "at room view8", *at, *K8, "--balance", "view"),
        }
        fb = render("paper_room", tmp, "at room fb8", "--level", "at", "--frames", "0:1", *K8, "--balance", "feedback")
        fb["frames"] = fb["frames"][1:]
        shown["room, feedback, subdivide 8"] = fb

        # The animation, analytic.
        an = ["--level", "analytic", "--frames", frames]
        runs = {name: render(scene, tmp, "an " + name, *an, *flags) for name, (scene, flags, _) in POLICIES.items()}
        one = {name: render(scene, tmp, "an " + name, *an, *flags) for name, (scene, flags) in ONE_IU.items()}
        shared = render("paper_room", tmp, "an room feedback shared", *an, *K8, "--balance", "feedback", "@shared")
        shared_san = render("paper_room", tmp, "an room sa_n shared", *an, *K8, "--balance", "sa_n", "@shared")

        # at and analytic agree on frame 0 (they must, under the ideal architecture).
        for name in ("room, paper", "room, sa_n, subdivide 8", "room, view, subdivide 8", "polygons, paper"):
            fa, fn = shown[name]["frames"][0], runs[name]["frames"][0]
            same = fa["makespan_cycles"] == fn["makespan_cycles"] and \
                all(x["cycles"] == y["cycles"] for x, y in zip(fa["ius"], fn["ius"]))
            print(f"at vs analytic, {name}, frame 0: {'identical' if same else 'DIFFERENT'} "
                  f"(makespan {fa['makespan_cycles']:,} / {fn['makespan_cycles']:,})")

        rs = draw(a.out, shown, runs)
        tables(frames, shown, runs, one, shared, shared_san, rs)
    print(f"\nplots: {a.out}/fig7_per_iu_cycles.png, fig8_primitive_vs_san.png, fig10_room_balanced.png, "
          "fig10_efficiency_per_frame.png")

