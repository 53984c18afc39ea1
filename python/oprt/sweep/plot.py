"""Plots from a sweep's aggregate.csv (written by scripts/sweep; docs/sweeps.md).

  scripts/plot_sweep OUT/aggregate.csv --out DIR [--bars SELECTOR]... [--frame N]
  scripts/plot_sweep OUT/aggregate.csv --out DIR --pareto [--budget MM2] [--table]

Writes into DIR, for each scene:
  scaling_<scene>.png        makespan and parallel efficiency against IU count, one line per
                             policy (and per value of every other varied parameter)
  effect_<param>_<scene>.png the same figures against FIFO depth, bus bandwidth, bus arbitration,
                             memory latency, object-memory capacity or cache line size, for
                             those that vary in the sweep
  cache_<scene>.png          where the object-memory capacity (memory.sram_bytes) varies: the
                             caches' hit rate, the share of unit time spent waiting for object
                             memory, and the makespan against the unlimited memory's, against
                             capacity, one line per cache line size (and other varied parameter)
With --table, it also prints per scene a markdown table of the same figures: a row per value of
the swept axis (the IU count when it varies), a column per combination of the other varied
parameters, each cell "makespan in million cycles (parallel efficiency)", marked * where the
engine instantiated fewer units than requested.
And, with --bars, bars.png: per-IU stacked cycles (sphere, transform, primitive, stall, idle) of
the chosen points, one panel each, read from the points' stats.json. A SELECTOR is
key=value[,key=value...] over the aggregate's columns, e.g. scene=paper_room,ius=32,balance=sa_n
(scene matches the file name without directory and extension).
With --pareto (a sweep whose runs report area and energy: oprt's technology table), it writes
instead, per scene and technology table, pareto_<scene>[_<table>].png: frame time against area
and energy per frame against frame time, each point coloured by IU model, the Pareto-optimal
points (no other point is as good in both and better in one) filled and joined, the others
hollow. With --table it prints each Pareto front as a markdown table; with --budget MM2, the
fastest configuration whose area fits the budget (the one a designer with that budget picks).
Needs matplotlib (Debian's python3-matplotlib).
"""
import argparse
import csv
import json
import os
import sys
from collections import defaultdict

from .. import plots
from ..pareto import pareto_front
plt = plots.pyplot("plots")
import matplotlib
import matplotlib.ticker

PARAMS = ["frames", "resolution", "ius", "balance", "subdivide", "split", "level", "quantum_ns", "accel", "kernel",
          "precision", "ray_fifo_depth", "bus.model", "bus.bytes_per_cycle", "bus.arbitration_cycles", "memory.model",
          "memory.latency_cycles", "memory.bytes_per_cycle", "gpp.cycles_per_ray", "gpp.cycles_per_hit", "clock_mhz",
          "costs.sphere", "costs.transform", "costs.triangle", "top", "memory.sram_bytes", "memory.cache.line_bytes",
          "memory.cache.ways", "memory.cache.replacement", "memory.dram.latency_cycles", "memory.dram.bytes_per_cycle",
          "memory.dram.units_per_channel", "iu.model", "iu.rays_in_flight", "iu.stack.depth", "iu.fp_latency.add",
          "iu.fp_latency.multiply", "iu.adders", "iu.multipliers", "iu.triangle_ii", "tech"]
EFFECTS = {"ray_fifo_depth": "ray FIFO depth (rays; 0 = unbounded)", "bus.bytes_per_cycle": "bus bandwidth (bytes/cycle)",
           "bus.arbitration_cycles": "bus arbitration (cycles)", "memory.latency_cycles": "memory latency (cycles)",
           "memory.sram_bytes": "object memory per unit (bytes; 0 = unlimited)",
           "memory.cache.line_bytes": "cache line (bytes)"}
UNBOUNDED = {"ray_fifo_depth": "unbounded FIFO", "memory.sram_bytes": "unlimited memory"}
LABELS = {"balance": "{}", "subdivide": "K={}", "split": "split {}", "ray_fifo_depth": "FIFO {}", "bus.model": "{} bus",
          "bus.bytes_per_cycle": "bus {} B/cycle", "memory.latency_cycles": "memory latency {}", "level": "{}",
          "precision": "{}", "ius": "{} IUs", "memory.cache.line_bytes": "{} B lines", "memory.sram_bytes": "{} B",
          "memory.cache.ways": "{} ways", "top": "top {}"}
PHASES = [("node", "node test", "#8c613c"), ("sphere", "sphere test", "#4878d0"), ("transform", "transform", "#ee854a"),
          ("box", "box test", "#956cb4"),
          ("primitive", "primitive test", "#6acc64"), ("stall", "stall", "#d65f5f"), ("idle", "idle", "#d9d9d9")]


def scene_name(path):
    return os.path.splitext(os.path.basename(path))[0]


def number(text):
    try:
        v = float(text)
        return int(v) if v.is_integer() else v
    except ValueError:
        return text


def load_points(csv_file, frame):
    """One record per point: its parameters and its figures averaged over its frames (or at `frame`)."""
    by_point = defaultdict(list)
    with open(csv_file, newline="") as f:
        for row in csv.DictReader(f):
            if frame is None or int(row["frame"]) == frame:
                by_point[row["point"]].append(row)
    points = []
    for rows in by_point.values():
        p = {k: number(v) for k, v in rows[0].items()}
        p["scene"] = scene_name(rows[0]["scene"])
        for key in ("makespan_cycles", "parallel_efficiency", "idle_fraction", "units", "frame_time_s", "energy_j"):
            if all(r.get(key, "") != "" for r in rows):
                p[key] = sum(float(r[key]) for r in rows) / len(rows)
        for key in ("memory_hits", "memory_misses", "memory_stall_cycles", "busy_cycles"):  # summed over frames
            p[key] = sum(float(r.get(key) or 0) for r in rows)
        points.append(p)
    return points


def varied(points, names):
    return [n for n in names if len({str(p.get(n)) for p in points}) > 1]


def series_label(key, names):
    text = lambda n, v: UNBOUNDED[n] if n in UNBOUNDED and v == 0 else LABELS.get(n, n + "={}").format(v)
    return ", ".join(text(n, v) for n, v in zip(names, key)) or "all points"


def natural(key):
    """Sort key: numbers by value (0, the unbounded FIFO, last), then text."""
    return tuple((0, v if v else float("inf"), "") if isinstance(v, (int, float)) else (1, 0, str(v)) for v in key)


def line_styles(keys, names):
    """Colour by the first varied parameter (the policy when it varies), line style by the rest;
    a numeric first parameter gets colours in order from a sequential map."""
    firsts = sorted({k[0] for k in keys}, key=lambda v: natural((v,))) if names else [None]
    rests = sorted({k[1:] for k in keys}, key=natural) if names else [()]
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    if names and all(isinstance(v, (int, float)) for v in firsts) and len(firsts) > 2:
        colours = [matplotlib.cm.viridis(i / (len(firsts) - 1) * 0.9) for i in range(len(firsts))]
    dashes = ["-", "--", ":", "-."]
    markers = ["o", "s", "^", "D", "v", "P"]
    return {k: dict(color=colours[firsts.index(k[0] if names else None) % len(colours)],
                    linestyle=dashes[rests.index(k[1:] if names else ()) % len(dashes)],
                    marker=markers[rests.index(k[1:] if names else ()) % len(markers)]) for k in keys}


def against(points, x, xlabel, title, out_file, log_x):
    """Makespan and efficiency against parameter x, one line per combination of the other varied parameters."""
    values = sorted({p[x] for p in points})
    # A FIFO depth or a capacity of 0 means unbounded: drawn to the right of the largest value.
    unbounded = x in UNBOUNDED and values[0] == 0 and len(values) > 1
    at = (lambda v: v if v else values[-1] * (4 if log_x else 1.25)) if unbounded else (lambda v: v)
    others = [n for n in varied(points, PARAMS) if n != x]
    series = defaultdict(list)
    for p in points:
        series[tuple(p.get(n) for n in others)].append(p)
    styles = line_styles(series, others)
    fig, (ax_m, ax_e) = plt.subplots(1, 2, figsize=(13, 4.8), constrained_layout=True)
    capped = False
    for key in sorted(series, key=natural):
        pts = sorted(series[key], key=lambda p: at(p[x]))
        xs = [at(p[x]) for p in pts]
        style = styles[key]
        for ax, y in ((ax_m, [p["makespan_cycles"] / 1e6 for p in pts]), (ax_e, [p["parallel_efficiency"] for p in pts])):
            ax.plot(xs, y, label=series_label(key, others), **style)
            if x == "ius":  # hollow marker: fewer units than requested (no more units than spheres)
                few = [(xv, yv) for xv, yv, p in zip(xs, y, pts) if p["units"] < p["ius"]]
                if few:
                    capped = True
                    ax.plot(*zip(*few), linestyle="none", marker=style["marker"], markersize=9,
                            markerfacecolor="white", markeredgecolor=style["color"])
    if x == "ius":
        best_1 = min((p["makespan_cycles"] for p in points if p["ius"] == 1), default=None)
        if best_1:
            xs = sorted({p["ius"] for p in points})
            ax_m.plot(xs, [best_1 / 1e6 / n for n in xs], color="grey", linewidth=1, linestyle=(0, (1, 3)),
                      label="ideal: best 1-IU makespan / N")
    ax_m.set_ylabel("makespan (million cycles)")
    ax_e.set_ylabel("parallel efficiency (busy / (units x makespan))")
    ax_e.set_ylim(0, 1.05)
    for ax in (ax_m, ax_e):
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
        if log_x:
            ax.set_xscale("log", base=2)
            ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.set_xticks([at(v) for v in values], [("unbounded" if unbounded and not v else f"{v:g}") for v in values])
    spans = [p["makespan_cycles"] for p in points]
    if (log_x and x == "ius") or max(spans) > 8 * min(spans):
        ax_m.set_yscale("log")
        ax_m.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax_m.yaxis.set_minor_formatter(matplotlib.ticker.FuncFormatter(
            lambda v, _: f"{v:g}" if str(f"{v:g}")[0] in "25" else ""))
    handles, labels = ax_m.get_legend_handles_labels()
    ax_e.legend(handles, labels, loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=8,
               title="hollow marker: fewer units than\nrequested (one sphere per unit)" if capped else None,
               title_fontsize=8)
    fig.suptitle(title)
    fig.savefig(out_file, dpi=110)
    plt.close(fig)
    print(f"plot_sweep: wrote {out_file}")


def table(points, x, title):
    """The markdown table of --table: rows = values of x, columns = the other varied parameters."""
    others = [n for n in varied(points, PARAMS) if n != x]
    series = defaultdict(dict)
    for p in points:
        series[tuple(p.get(n) for n in others)][p[x]] = p
    keys = sorted(series, key=natural)
    values = sorted({p[x] for p in points}, key=lambda v: natural((v,)))
    print(f"\n**{title}**\n")
    print(f"| {x} | " + " | ".join(series_label(k, others) for k in keys) + " |")
    print("|---:|" + "---:|" * len(keys))
    for v in values:
        cells = []
        for k in keys:
            p = series[k].get(v)
            if p is None:
                cells.append("")
                continue
            mark = "*" if x == "ius" and p["units"] < p["ius"] else ""
            cells.append(f"{p['makespan_cycles'] / 1e6:.1f} ({p['parallel_efficiency']:.2f}){mark}")
        print(f"| {v:g} | " if isinstance(v, (int, float)) else f"| {v} | ", end="")
        print(" | ".join(cells) + " |")


def matches(point, selector):
    for term in selector.split(","):
        key, _, value = term.partition("=")
        if key not in point:
            sys.exit(f"plot_sweep: --bars {selector}: no column {key!r}")
        if str(point[key]) != value and str(number(value)) != str(point[key]):
            return False
    return True


def bars(points, selectors, csv_file, frame, out_file):
    """Per-IU stacked cycles of the chosen points, one panel each, from the points' stats.json."""
    chosen = []
    for sel in selectors:
        found = [p for p in points if matches(p, sel)]
        if not found:
            sys.exit(f"plot_sweep: --bars {sel}: no point matches")
        chosen += [p for p in found if p not in chosen]
    names = [n for n in varied(points, PARAMS) if n != "frames"]
    fig, axes = plt.subplots(len(chosen), 1, figsize=(12, 2.6 * len(chosen) + 0.6), sharey=True, squeeze=False,
                             constrained_layout=True)
    for ax, p in zip(axes[:, 0], chosen):
        with open(os.path.join(os.path.dirname(os.path.abspath(csv_file)), p["dir"], "stats.json")) as f:
            stats = json.load(f)
        fr = next(fr for fr in stats["frames"] if frame is None or fr["frame"] == frame)
        ids = [u["id"] for u in fr["ius"]]
        bottom = [0.0] * len(ids)
        for key, label, colour in PHASES:
            heights = [u["cycles"].get(key, 0) / 1e6 for u in fr["ius"]]  # box: --accel bvh only
            ax.bar(ids, heights, bottom=bottom, color=colour, label=label, width=0.8)
            bottom = [b + h for b, h in zip(bottom, heights)]
        ax.set_title(f"{p['scene']}, " + ", ".join(f"{n}={p[n]}" for n in names if n != "scene")
                     + f": {len(ids)} units, frame {fr['frame']}, efficiency {fr['parallel_efficiency']:.2f}", fontsize=10)
        ax.set_ylabel("million cycles")
        ax.set_xlim(-0.6, len(ids) - 0.4)
        ax.set_xticks(ids if len(ids) <= 32 else ids[::2])
        ax.tick_params(axis="x", labelsize=7)
    axes[-1, 0].set_xlabel("intersection unit")
    axes[0, 0].legend(ncol=5, fontsize=8, loc="lower right", bbox_to_anchor=(1, 1.12))
    fig.savefig(out_file, dpi=110)
    plt.close(fig)
    print(f"plot_sweep: wrote {out_file}")


def cache_effect(points, title, out_file):
    """Caches against object-memory capacity: hit rate, share of unit time waiting for object
    memory (stall / (busy + stall)), makespan over the unlimited memory's (capacity 0) of the
    same other parameters; one line per combination of the other varied parameters."""
    x = "memory.sram_bytes"
    others = [n for n in varied(points, PARAMS) if n != x]
    series = defaultdict(list)
    for p in points:
        series[tuple(p.get(n) for n in others)].append(p)
    styles = line_styles(series, others)
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8), constrained_layout=True)
    for key in sorted(series, key=natural):
        pts = series[key]
        unlimited = [p for p in pts if p[x] == 0]
        limited = sorted((p for p in pts if p[x] > 0), key=lambda p: p[x])
        if not limited:
            continue
        xs = [p[x] / 1024 for p in limited]
        lookups = [p["memory_hits"] + p["memory_misses"] for p in limited]
        hit = [p["memory_hits"] / n if n else float("nan") for p, n in zip(limited, lookups)]
        stall = [p["memory_stall_cycles"] / max(1, p["busy_cycles"] + p["memory_stall_cycles"]) for p in limited]
        style = styles[key]
        axes[0].plot(xs, hit, label=series_label(key, others), **style)
        axes[1].plot(xs, stall, **style)
        if unlimited:
            axes[2].plot(xs, [p["makespan_cycles"] / unlimited[0]["makespan_cycles"] for p in limited], **style)
    for ax, ylabel in zip(axes, ("hit rate (line lookups of the caches)", "unit time waiting for object memory",
                                 "makespan / unlimited memory's")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("object memory per unit (KiB)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
    axes[2].axhline(1, color="grey", linewidth=0.8)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.savefig(out_file, dpi=110)
    plt.close(fig)
    print(f"plot_sweep: wrote {out_file}")


def config_label(p):
    model = p.get("iu.model") or "serial"
    text = f"{model}, {p['ius']} IUs, FIFO {p['ray_fifo_depth'] or 'unbounded'}"
    if model == "pipelined":
        text += f", triangle II {p.get('iu.triangle_ii', '?')}"
    # The axes a sweep may add beyond those: the structures inside and over the spheres, the memory.
    if p.get("accel") not in (None, "", "brute"):
        text += f", {p['accel']}"
    if p.get("top") not in (None, "", "flat"):
        text += f", top {p['top']}"
    if str(p.get("memory.sram_bytes", "0") or "0") not in ("0", "0.0"):
        text += f", {int(float(p['memory.sram_bytes'])) // 1024} KB"
    return text


MODEL_COLOURS = plots.MODEL_COLOURS


def pareto(points, title, out_file, budget, print_table):
    """Frame time against area, and energy against frame time; Pareto points filled and joined."""
    for p in points:
        p["frame_ms"] = p["frame_time_s"] * 1e3
        p["energy_mj"] = p["energy_j"] * 1e3
    fig, axes = plt.subplots(1, 2, figsize=(13, 5), constrained_layout=True)
    for ax, (x, y, xlabel, ylabel) in zip(axes, (("area_mm2", "frame_ms", "area (mm2)", "frame time (ms)"),
                                                 ("frame_ms", "energy_mj", "frame time (ms)", "energy per frame (mJ)"))):
        front = pareto_front(points, x, y)
        for model in sorted({p.get("iu.model") or "serial" for p in points}):
            mine = [p for p in points if (p.get("iu.model") or "serial") == model]
            colour = MODEL_COLOURS.get(model, "grey")
            ax.scatter([p[x] for p in mine if p not in front], [p[y] for p in mine if p not in front], s=28,
                       facecolors="none", edgecolors=colour, label=f"{model}")
            ax.scatter([p[x] for p in mine if p in front], [p[y] for p in mine if p in front], s=40, color=colour,
                       label=f"{model}, Pareto-optimal")
        ax.step([p[x] for p in front], [p[y] for p in front], where="post", color="black", linewidth=0.8, alpha=0.6)
        if budget is not None and x == "area_mm2":
            ax.axvline(budget, color="grey", linestyle="--", linewidth=1, label=f"budget {budget:g} mm2")
        # Log scale for a figure spanning more than 4x, plain numbers on the ticks.
        plots.log_if_wide(ax, [p[x] for p in points], [p[y] for p in points], minor=True)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        if print_table:
            print(f"\n**{title}: Pareto front of {ylabel} against {xlabel}**\n")
            print("| configuration | area (mm2) | frame time (ms) | energy per frame (mJ) |")
            print("|---|---:|---:|---:|")
            for p in front:
                print(f"| {config_label(p)} | {p['area_mm2']:.2f} | {p['frame_ms']:.3f} | {p['energy_mj']:.3f} |")
    if budget is not None:
        fits = [p for p in points if p["area_mm2"] <= budget]
        if fits:
            best = min(fits, key=lambda p: (p["frame_ms"], p["energy_mj"]))
            print(f"plot_sweep: {title}: within {budget:g} mm2 the fastest is {config_label(best)}: "
                  f"{best['area_mm2']:.2f} mm2, {best['frame_ms']:.3f} ms, {best['energy_mj']:.3f} mJ per frame")
        else:
            smallest = min(points, key=lambda p: p["area_mm2"])
            print(f"plot_sweep: {title}: no configuration fits {budget:g} mm2 "
                  f"(the smallest, {config_label(smallest)}, takes {smallest['area_mm2']:.2f} mm2)")
    fig.suptitle(title)
    fig.savefig(out_file, dpi=110)
    plt.close(fig)
    print(f"plot_sweep: wrote {out_file}")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="plot_sweep", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("aggregate", metavar="AGG.csv", help="a sweep's aggregate.csv")
    ap.add_argument("--out", required=True, help="directory for the PNG files")
    ap.add_argument("--bars", action="append", default=[], metavar="SELECTOR",
                    help="per-IU stacked bars for the points matching key=value[,key=value...] (repeatable)")
    ap.add_argument("--bars-file", default="bars.png", help="file name of the bars figure (default: bars.png)")
    ap.add_argument("--frame", type=int, help="use this frame only (default: the mean over the frames)")
    ap.add_argument("--table", action="store_true", help="also print the figures as markdown tables")
    ap.add_argument("--pareto", action="store_true",
                    help="frame time against area and energy against frame time, Pareto points marked")
    ap.add_argument("--budget", type=float, metavar="MM2", help="with --pareto: the fastest configuration within this area")
    a = ap.parse_args(argv)
    points = load_points(a.aggregate, a.frame)
    if not points:
        sys.exit(f"plot_sweep: {a.aggregate}: no finished points")
    os.makedirs(a.out, exist_ok=True)
    if a.pareto:
        costed = [p for p in points if "energy_j" in p and p.get("area_mm2", "") != "" and "frame_time_s" in p]
        if not costed:
            sys.exit(f"plot_sweep: {a.aggregate}: no point reports area and energy (run the sweep with a current oprt)")
        for scene in sorted({p["scene"] for p in costed}):
            tables = sorted({str(p.get("tech", "")) for p in costed if p["scene"] == scene})
            for tech in tables:
                mine = [p for p in costed if p["scene"] == scene and str(p.get("tech", "")) == tech]
                tag = os.path.splitext(os.path.basename(tech.split(" ")[0]))[0] if len(tables) > 1 else ""
                title = f"{scene}" + (f", {tag}" if tag else "")
                pareto(mine, title, os.path.join(a.out, f"pareto_{scene}" + (f"_{tag}" if tag else "") + ".png"),
                       a.budget, a.table)
        return
    for scene in sorted({p["scene"] for p in points}):
        mine = [p for p in points if p["scene"] == scene]
        if "ius" in varied(mine, PARAMS):
            against(mine, "ius", "intersection units requested", f"{scene}: scaling with the number of IUs",
                    os.path.join(a.out, f"scaling_{scene}.png"), log_x=True)
            if a.table:
                table(mine, "ius", f"{scene}: makespan in million cycles (parallel efficiency)")
        for param, xlabel in EFFECTS.items():
            if param in varied(mine, PARAMS):
                values = sorted({p[param] for p in mine})
                positive = [v for v in values if v > 0]
                log_x = len(positive) > 1 and positive[-1] / positive[0] >= 8 and (values[0] > 0 or param == "ray_fifo_depth")
                against(mine, param, xlabel, f"{scene}: effect of the {xlabel.split(' (')[0]}",
                        os.path.join(a.out, f"effect_{param.replace('.', '_')}_{scene}.png"), log_x)
                if a.table and "ius" not in varied(mine, PARAMS):
                    table(mine, param, f"{scene}: makespan in million cycles (parallel efficiency) against {xlabel}")
        if "memory.sram_bytes" in varied(mine, PARAMS) and any(p.get("memory_hits") or p.get("memory_misses") for p in mine):
            cache_effect(mine, f"{scene}: object memory as a cache", os.path.join(a.out, f"cache_{scene}.png"))
    if a.bars:
        bars(points, a.bars, a.aggregate, a.frame, os.path.join(a.out, a.bars_file))

