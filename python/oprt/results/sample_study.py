"""Sampled simulation's error study (docs/results.md, "Sampled simulation"): for each case (a
scene, a resolution, the options of one render) it renders the full frame once and a sample of
its pixels at each fraction and seed, at the same level,

  oprt render SCENE --frames 0 --resolution R OPTIONS --level L [--sample 1/N --seed S]

and compares each estimate (stats.json frames[0].sample.estimate) with the full run's figure:
the makespan (frame time), the energy, the busiest unit's busy cycles, the bus bytes and the
DRAM bytes; whether the stated 95 % interval covers the full run's figure; the wall time of
each run. It writes runs.csv (one row per sampled run), summary.md (the tables) and plots in
--plots, and prints the tables.

  scripts/sample_study [--out DIR] [--plots DIR] [--oprt PATH] [--fractions 4,16,64]
                       [--seeds 5] [--level analytic] [--blocks design,paper,pipelined] [--quick]
"""
import csv
import json
import math
import os
import statistics
import sys

from .. import paths
from ..render import render, scenes_present, script_arguments

ROOM = os.path.join(paths.SCENES, "paper_room.json")
POLYGONS = os.path.join(paths.SCENES, "paper_polygons.json")
KITCHEN = os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff")
MUSEUM = os.path.join(paths.SHARED, "bart", "museum", "museum5.aff")
IDEAL = os.path.join(paths.ARCH, "paper.json")
CONTENDED = os.path.join(paths.ARCH, "contended.json")
PIPELINED = os.path.join(paths.ARCH, "pipelined.json")

def busiest(sample):
    """The busiest unit's estimate and interval (its index: the full run's busiest may differ)."""
    per = sample["estimate"]["busy_cycles_per_unit"]
    u = max(range(len(per)), key=lambda i: per[i])
    return per[u], sample["interval"]["busy_cycles_per_unit"][u]


def key(name):
    """An estimate of stats.json's sample by its key: (estimate, [low, high]) or None."""
    return lambda sample: (sample["estimate"][name], sample["interval"][name]) if name in sample["estimate"] else None


#: The figures compared: how to read the full run's figure, and the sampled run's estimate and interval.
FIGURES = {
    "makespan_cycles": (lambda f: f["makespan_cycles"], key("makespan_cycles")),
    "energy_j": (lambda f: f["energy_j"]["total"], key("energy_j")),
    "busy_cycles_max": (lambda f: max(u["busy_cycles"] for u in f["ius"]), busiest),
    "bus_bytes": (lambda f: f["bus"]["bytes"], key("bus_bytes")),
    "dram_bytes": (lambda f: sum(u["memory"]["dram_bytes"] for u in f["ius"]), key("dram_bytes")),
}


def design_cases():
    """Scenes x architecture (ideal, contended) x memory (on-chip, 16 KB caches) x route
    (broadcast under sa_n, multicast and ordered under spatial), with a BVH in every sphere."""
    scenes = [("room", ROOM, "128x128"), ("room", ROOM, "256x256"), ("polygons", POLYGONS, "128x128"),
              ("kitchen", KITCHEN, "256x192"), ("museum", MUSEUM, "256x256")]
    for name, scene, res in scenes:
        for arch_name, arch in (("ideal", IDEAL), ("contended", CONTENDED)):
            for memory in ("on-chip", "16K"):
                for route, balance in (("broadcast", "sa_n"), ("multicast", "spatial"), ("ordered", "spatial")):
                    args = ["--arch", arch, "--accel", "bvh", "--balance", balance, "--route", route]
                    if memory != "on-chip":
                        args += ["--sram", memory]
                    yield (f"{name} {res} {arch_name} {memory} {route}", scene, res, args)


def paper_cases():
    """The paper's own setting: brute force, one sphere per unit, the ideal architecture."""
    for name, scene in (("room", ROOM), ("polygons", POLYGONS)):
        for res in ("128x128", "256x256", "512x512"):
            yield (f"{name} {res} paper brute", scene, res, ["--arch", IDEAL, "--accel", "brute", "--balance", "paper"])


def fifo_arch(base, depth, folder):
    """An architecture file: `base` with ray FIFOs of `depth` (written into `folder`)."""
    with open(base) as f:
        arch = json.load(f)
    arch["ray_fifo_depth"] = depth
    path = os.path.join(folder, f"{os.path.splitext(os.path.basename(base))[0]}_fifo{depth}.json")
    os.makedirs(folder, exist_ok=True)
    with open(path, "w") as f:
        json.dump(arch, f)
    return path


def fifo_cases(folder):
    """Bounded ray FIFOs on the ideal bus (serial units, 8 of them) and pipelined units (FIFOs of
    256), where the order of the rays matters."""
    for name, scene, res in (("room", ROOM, "256x256"), ("kitchen", KITCHEN, "256x192")):
        for depth in (16, 256):
            yield (f"{name} {res} serial fifo {depth}", scene, res,
                   ["--arch", fifo_arch(IDEAL, depth, folder), "--ius", "8", "--accel", "bvh", "--balance", "sa_n"])
        yield (f"{name} {res} pipelined fifo 256", scene, res,
               ["--arch", fifo_arch(PIPELINED, 256, folder), "--ius", "8", "--accel", "bvh", "--balance", "sa_n"])


def quick_cases(folder):
    """A few of each kind, for a look in a minute."""
    yield ("room 128x128 ideal broadcast", ROOM, "128x128", ["--arch", IDEAL, "--accel", "bvh", "--balance", "sa_n"])
    yield ("room 128x128 contended broadcast", ROOM, "128x128", ["--arch", CONTENDED, "--accel", "bvh", "--balance", "sa_n"])
    yield ("room 128x128 paper brute", ROOM, "128x128", ["--arch", IDEAL, "--accel", "brute", "--balance", "paper"])
    yield ("polygons 128x128 paper brute", POLYGONS, "128x128", ["--arch", IDEAL, "--accel", "brute", "--balance", "paper"])


BLOCKS = {"design": lambda folder: design_cases(), "paper": lambda folder: paper_cases(), "fifo": fifo_cases,
          "quick": quick_cases}


def relative(estimate, truth):
    return (estimate - truth) / truth if truth else (0.0 if estimate == 0 else math.inf)


def compare(full, sampled):
    """Per figure: the estimate's relative error against the full run and whether the interval
    covers the full run's figure."""
    s = sampled["sample"]
    row = {"trusted": s["trusted"], "flags": " ".join(s["flags"])}
    for name, (truth_of, estimate_of) in FIGURES.items():
        got = estimate_of(s)
        if got is None:
            continue
        (est, (low, high)), truth = got, truth_of(full)
        row[f"{name}_error"] = relative(est, truth)
        row[f"{name}_covered"] = low <= truth <= high
        row[f"{name}_halfwidth"] = relative(high, est) if est else 0.0
    return row


def run_case(case, a, writer):
    name, scene, res, args = case
    base = [scene, "--frames", "0", "--resolution", res, "--level", a.level, "--threads", "1", *args]
    slug = name.replace(" ", "_")
    full, full_wall = render(base, os.path.join(a.out, "runs", slug, "full"), a.oprt, "sample_study", timed=True)
    rows = []
    for n in a.fractions:
        for seed in range(a.seeds):
            out = os.path.join(a.out, "runs", slug, f"1_{n}_{seed}")
            st, wall = render(base + ["--sample", f"1/{n}", "--seed", str(seed)], out, a.oprt, "sample_study", timed=True)
            row = {"case": name, "fraction": f"1/{n}", "seed": seed, "full_wall_s": full_wall, "wall_s": wall,
                   **compare(full["frames"][0], st["frames"][0])}
            writer.writerow(row)
            rows.append(row)
    return rows


def percent(x):
    return f"{100 * x:.2f}%"


def summary(rows, fractions):
    """The tables: per fraction (every run, the trusted ones, the flagged ones) the median and
    worst |error| of each figure, the coverage of the frame time's interval, the median speed-up;
    then per case at 1/16."""
    lines = ["| fraction | runs | frame time median | worst | coverage | energy median | worst | busiest unit median |"
             " bus bytes median | speed-up median |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for n in fractions:
        for which, keep in (("", lambda x: True), (" trusted", lambda x: x["trusted"]),
                            (" flagged", lambda x: not x["trusted"])):
            r = [x for x in rows if x["fraction"] == f"1/{n}" and keep(x)]
            if not r:
                continue
            ft = [abs(x["makespan_cycles_error"]) for x in r]
            en = [abs(x["energy_j_error"]) for x in r if x.get("energy_j_error", "") != ""]
            busy = [abs(x["busy_cycles_max_error"]) for x in r]
            bus = [abs(x["bus_bytes_error"]) for x in r if x.get("bus_bytes_error", "") != ""]
            cover = sum(1 for x in r if x["makespan_cycles_covered"]) / len(r)
            speed = [x["full_wall_s"] / x["wall_s"] for x in r]
            lines.append(f"| 1/{n}{which} | {len(r)} | {percent(statistics.median(ft))} | {percent(max(ft))} | "
                         f"{percent(cover)} | {percent(statistics.median(en)) if en else '-'} | "
                         f"{percent(max(en)) if en else '-'} | {percent(statistics.median(busy))} | "
                         f"{percent(statistics.median(bus)) if bus else '-'} | {statistics.median(speed):.1f}x |")
    lines += ["", "| case (1/16) | frame time error (seeds) | covered | energy error median | trusted |", "|---|---|---:|---:|---|"]
    for case in dict.fromkeys(x["case"] for x in rows):
        r = [x for x in rows if x["case"] == case and x["fraction"] == "1/16"]
        if not r:
            continue
        errs = " ".join(f"{100 * x['makespan_cycles_error']:+.1f}" for x in r)
        cov = sum(1 for x in r if x["makespan_cycles_covered"])
        en = statistics.median(abs(x["energy_j_error"]) for x in r)
        flags = sorted({f for x in r for f in x["flags"].split()})
        lines.append(f"| {case} | {errs} | {cov}/{len(r)} | {percent(en)} | "
                     f"{'yes' if all(x['trusted'] for x in r) else ', '.join(flags)} |")
    return "\n".join(lines)


def category(case):
    """The study's kinds of case, for the plots."""
    for key, name in (("paper", "paper, brute"), ("pipelined", "pipelined"), ("fifo", "FIFOs, ideal bus"),
                      ("contended", "contended"), ("16K", "ideal, caches")):
        if key in case:
            return name
    return "ideal"


def plots(rows, fractions, folder):
    """Error against fraction (trusted and flagged runs side by side), the error by kind of case
    at 1/16, and each 1/16 run's interval against the full run."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(folder, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 4))
    for i, n in enumerate(fractions):
        for trusted, dx, colour in ((True, -0.15, "tab:blue"), (False, 0.15, "tab:red")):
            ys = [100 * x["makespan_cycles_error"] for x in rows if x["fraction"] == f"1/{n}" and x["trusted"] == trusted]
            ax.scatter([i + dx + (j % 9 - 4) * 0.015 for j in range(len(ys))], ys, s=5, c=colour,
                       label=("trusted" if trusted else "flagged") if i == 0 else None)
    ax.set_xticks(range(len(fractions)), [f"1/{n}" for n in fractions])
    ax.set_yscale("symlog", linthresh=5)
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_ylabel("frame time error (%, symlog)")
    ax.set_title("Sampled estimate against the same level's full run")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "error_by_fraction.png"), dpi=120)
    plt.close(fig)
    r = [x for x in rows if x["fraction"] == "1/16"]
    kinds = list(dict.fromkeys(category(x["case"]) for x in r))
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.boxplot([[100 * x["makespan_cycles_error"] for x in r if category(x["case"]) == k] for k in kinds], labels=kinds)
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_ylabel("frame time error at 1/16 (%)")
    ax.set_title("Error by kind of case (1/16)")
    plt.setp(ax.get_xticklabels(), rotation=20)
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "error_by_kind_1_16.png"), dpi=120)
    plt.close(fig)
    r.sort(key=lambda x: (not x["trusted"], x["makespan_cycles_error"]))
    fig, ax = plt.subplots(figsize=(7, max(3, 0.02 * len(r))))
    for j, x in enumerate(r):
        e, h = 100 * x["makespan_cycles_error"], 100 * x["makespan_cycles_halfwidth"]
        ax.errorbar(e, j, xerr=h, fmt="o", ms=1.5, lw=0.5,
                    color=("tab:blue" if x["trusted"] else "tab:orange") if x["makespan_cycles_covered"] else "tab:red")
    ax.axvline(0, color="grey", lw=0.5)
    ax.set_xlabel("estimate and its 95 % interval, relative to the full run (%)")
    ax.set_yticks([])
    ax.set_title("1/16: trusted (blue, below) and flagged (orange) runs; red: the full run outside")
    fig.tight_layout()
    fig.savefig(os.path.join(folder, "intervals_1_16.png"), dpi=120)
    plt.close(fig)


def replot(folder, plots_folder, fractions):
    """The tables and plots again from a finished study's runs.csv."""
    with open(os.path.join(folder, "runs.csv")) as f:
        rows = list(csv.DictReader(f))
    for x in rows:
        for k, v in list(x.items()):
            if k.endswith(("_error", "_halfwidth", "wall_s")) and v != "":
                x[k] = float(v)
            elif k.endswith("_covered") or k == "trusted":
                x[k] = v == "True"
    print(summary(rows, fractions))
    plots(rows, fractions, plots_folder)


def main(argv=None):
    ap = script_arguments(__doc__, "sample_study", fractions="4,16,64", seeds="5", level="analytic",
                          blocks="design,paper,fifo", plots=os.path.join(paths.REPO, "docs", "plots", "sample"))
    ap.add_argument("--replot", action="store_true", help="tables and plots again from --out's runs.csv")
    a = ap.parse_args(argv)
    a.fractions = [int(x) for x in a.fractions.split(",")]
    a.seeds = int(a.seeds)
    if a.replot:
        replot(a.out, a.plots, a.fractions)
        return 0
    cases = [c for b in a.blocks.split(",") for c in BLOCKS[b](os.path.join(a.out, "arch"))]
    os.makedirs(a.out, exist_ok=True)
    rows = []
    with open(os.path.join(a.out, "runs.csv"), "w", newline="") as f:
        fields = ["case", "fraction", "seed", "full_wall_s", "wall_s", "trusted", "flags"] + [
            f"{k}_{p}" for k in FIGURES for p in ("error", "covered", "halfwidth")]
        writer = csv.DictWriter(f, fieldnames=fields)
        writer.writeheader()
        for case in scenes_present(cases, "sample_study"):
            rows += run_case(case, a, writer)
            f.flush()
            print(f"sample_study: {case[0]} done", file=sys.stderr, flush=True)
    text = summary(rows, a.fractions)
    with open(os.path.join(a.out, "summary.md"), "w") as f:
        f.write(text + "\n")
    print(text)
    plots(rows, a.fractions, a.plots)
    return 0
