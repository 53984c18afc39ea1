"""Per-IU balance of frames from an `oprt render` stats.json: a markdown table and, with
--plot, stacked bars (sphere, transform, primitive, stall, idle per unit) like the paper's Fig. 7.

  scripts/per_iu STATS.json [STATS.json ...] [--frames 0,400] [--plot per_iu.png] [--title TEXT]

Several stats files (e.g. an early and a late run of one animation) are read as one list of
frames; --frames picks from it.

The table gives per frame: makespan, parallel efficiency (busy cycles over units x makespan),
idle fraction, the busiest and the least busy unit, and the spread max/mean of busy cycles.
"""
import argparse
import json
import sys

from .. import paths


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"per_iu: {path}: {e}")


def busy(u):
    c = u["cycles"]
    return c["sphere"] + c["transform"] + c["primitive"] + c.get("box", 0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("stats", nargs="+")
    ap.add_argument("--frames", help="comma-separated frame numbers (default: all)")
    ap.add_argument("--plot", help="write stacked per-IU bars of the chosen frames to this PNG")
    ap.add_argument("--title", default="")
    a = ap.parse_args(argv)
    frames = [f for path in a.stats for f in load(path)["frames"]]
    if a.frames:
        want = [int(x) for x in a.frames.split(",")]
        by = {f["frame"]: f for f in frames}
        missing = [w for w in want if w not in by]
        if missing:
            sys.exit(f"per_iu: no frame {missing[0]} in {' '.join(a.stats)} (they have {sorted(by)})")
        frames = [by[w] for w in want]

    print("| frame | units | makespan (cycles) | efficiency | idle | busiest unit (busy) | least busy unit (busy) | max/mean |")
    print("|---:|---:|---:|---:|---:|---|---|---:|")
    for f in frames:
        b = [busy(u) for u in f["ius"]]
        hi = max(range(len(b)), key=lambda i: b[i])
        lo = min(range(len(b)), key=lambda i: b[i])
        mean = sum(b) / len(b)
        print(f"| {f['frame']} | {len(b)} | {f['makespan_cycles']:,} | {f['parallel_efficiency']:.3f} | "
              f"{f['idle_fraction']:.3f} | {hi} ({b[hi]:,}) | {lo} ({b[lo]:,}) | {b[hi] / mean:.2f} |")

    if a.plot:
        try:
            import matplotlib
        except ImportError:  # first use on this machine: install it (scripts/setup plots)
            import os
            import subprocess
            subprocess.run([os.path.join(paths.REPO, "scripts", "setup"), "plots"], check=True)
            import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        colors = {"sphere": "#4c72b0", "box": "#8172b3", "transform": "#dd8452", "primitive": "#55a868",
                  "stall": "#c44e52", "idle": "#c8c8c8"}
        fig, axes = plt.subplots(1, len(frames), figsize=(5.5 * len(frames), 3.6), squeeze=False)
        for ax, f in zip(axes[0], frames):
            units = f["ius"]
            bottom = [0.0] * len(units)
            for k in colors:
                h = [u["cycles"].get(k, 0) / 1e6 for u in units]
                if not any(h):
                    continue
                ax.bar(range(len(units)), h, bottom=bottom, color=colors[k], label=k, width=0.85)
                bottom = [x + y for x, y in zip(bottom, h)]
            ax.set_title(f"{a.title} frame {f['frame']}\nmakespan {f['makespan_cycles'] / 1e6:,.0f} M cycles, "
                         f"efficiency {f['parallel_efficiency']:.3f}", fontsize=9)
            ax.set_xlabel("intersection unit")
            ax.set_ylabel("M cycles")
        axes[0][0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print(f"\nplot: {a.plot}")

