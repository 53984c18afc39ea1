"""Fan-out against parallel efficiency (issue 21, docs/results.md "Routing"): one panel per scene
from scripts/route_results --json FILE, a point per route and assignment, the Pareto points
(no other point has both a lower fan-out and a higher efficiency) ringed and labelled.

  scripts/plot_route ROWS.json --out docs/plots/route/fanout_efficiency.png
"""
import argparse
import json
import os

from .. import plots
from ..pareto import front_indices
plt = plots.pyplot("plots")

MARKERS = {"broadcast": "s", "multicast": "o", "ordered": "^"}
COLOURS = {"sa_n": "tab:red", "spatial 1": "tab:blue", "spatial 0.5": "tab:green", "feedback 0.5": "tab:purple",
           "feedback 1": "tab:olive", "feedback 1 +copies": "tab:orange", "feedback 0.5 +copies": "tab:pink"}


def pareto(rows):
    """The rows no other has both a lower fan-out and a higher efficiency (as low and as high, and better in one)."""
    return [rows[i] for i in front_indices([(r["fanout_mean"], -r["parallel_efficiency"]) for r in rows])]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rows")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    with open(a.rows) as f:
        rows = json.load(f)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.2 * len(scenes), 4), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        mine = [r for r in rows if r["scene"] == scene]
        for r in mine:
            ax.scatter(r["fanout_mean"], r["parallel_efficiency"], marker=MARKERS[r["route"]],
                       color=COLOURS.get(r["balance"], "k"), s=40)
        for r in pareto(mine):
            ax.scatter(r["fanout_mean"], r["parallel_efficiency"], s=160, facecolors="none", edgecolors="k")
            ax.annotate(f"{r['route']}, {r['balance']}", (r["fanout_mean"], r["parallel_efficiency"]), fontsize=6,
                        xytext=(4, -8), textcoords="offset points")
        first = mine[0]
        ax.set_title(f"{scene}: frames {first['frames']}, K = {first['k']}", fontsize=9)
        ax.set_xlabel("fan-out (units per ray, mean)")
        ax.set_ylabel("parallel efficiency")
        ax.set_xlim(left=0)
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    handles = [plt.Line2D([], [], marker=m, color="grey", linestyle="", label=k) for k, m in MARKERS.items()]
    used = {r["balance"] for r in rows}
    handles += [plt.Line2D([], [], marker="o", color=c, linestyle="", label=k) for k, c in COLOURS.items() if k in used]
    handles.append(plt.Line2D([], [], marker="o", markerfacecolor="none", markeredgecolor="k", markersize=10,
                              linestyle="", label="Pareto"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=120)
    print(a.out)

