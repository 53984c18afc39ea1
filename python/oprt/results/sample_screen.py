"""The search's screening fidelities side by side (docs/results.md, "Sampled simulation"):
random configurations of a space (scripts/examples/explore_full.json by default) priced at the
space's resolution (the target), by a sample of its pixels (`--sample 1/N`, the estimate) and
at a lower resolution (the resolution screen, its frame time and energy scaled by the pixel
ratio), each at the analytic level. Prints, per fidelity and objective, the scaled error
against the target (mean and largest), Spearman's and Kendall's rank correlations and the
wall time; writes configs.csv (one row per configuration).

  scripts/sample_screen [SPACE.json] [--configs 40] [--seed 0] [--sample 1/16] [--screen 32x32]
                        [--out DIR] [--oprt PATH]
"""
import csv
import json
import math
import os
import random
import statistics
import time

from .. import paths
from ..explore.evaluate import Oprt
from ..explore.fidelity import kendall, spearman
from ..explore.space import load_space
from ..render import render, script_arguments

OBJECTIVES = ("frame_time_s", "energy_j")


def random_config(space, rng):
    """A configuration drawn uniformly from each parameter's domain (log-uniform where it is log)."""
    config = {}
    for p in space.params:
        if p.kind == "choice":
            config[p.name] = rng.choice(p.values)
        elif p.kind == "int" and p.log and p.lo > 0:
            config[p.name] = int(round(math.exp(rng.uniform(math.log(p.lo), math.log(p.hi)))))
        elif p.kind == "int":
            config[p.name] = rng.randint(p.lo, p.hi)
        elif p.kind == "float":
            config[p.name] = rng.uniform(p.lo, p.hi)
        else:
            config[p.name] = p.value
    return config


def figures(stats, scale=1.0):
    """Frame time and energy of frame 0: the estimate's under --sample, else the frame's (times `scale`)."""
    f = stats["frames"][0]
    if "sample" in f:
        est = f["sample"]["estimate"]
        return {"frame_time_s": est["frame_time_s"], "energy_j": est["energy_j"]}
    return {"frame_time_s": f["frame_time_s"] * scale, "energy_j": f["energy_j"]["total"] * scale}


def pixels(resolution):
    w, h = resolution.split("x")
    return int(w) * int(h)


def price(oprt, space, config, folder, extra, resolution=None):
    """Renders the configuration's first scene at the analytic level; (stats or None, wall s)."""
    os.makedirs(folder, exist_ok=True)
    arch = os.path.join(folder, "arch.json")
    with open(arch, "w") as f:
        json.dump(oprt.arch_doc(config), f)
    args = [space.scene_files[0], "--arch", arch, "--level", "analytic", "--threads", "1",
            *oprt.tail_args(config, None, resolution, False), *extra]
    t0 = time.perf_counter()
    try:
        stats = render(args, os.path.join(folder, "out"), oprt.binary, "sample_screen")
    except SystemExit:  # refused (infeasible) or failed: left out
        return None, time.perf_counter() - t0
    return stats, time.perf_counter() - t0


def report(rows, fidelities):
    lines = ["| fidelity | objective | n | mean scaled error | largest | Spearman | Kendall | wall s (sum) |",
             "|---|---|---:|---:|---:|---:|---:|---:|"]
    for fid in fidelities:
        for obj in OBJECTIVES:
            pairs = [(r["target_" + obj], r[f"{fid}_{obj}"]) for r in rows]
            errs = [abs(s - t) / t for t, s in pairs if t]
            lines.append(f"| {fid} | {obj} | {len(pairs)} | {100 * statistics.mean(errs):.2f}% | {100 * max(errs):.2f}% | "
                         f"{spearman([p[0] for p in pairs], [p[1] for p in pairs]):.4f} | "
                         f"{kendall([p[0] for p in pairs], [p[1] for p in pairs]):.4f} | "
                         f"{sum(r[fid + '_wall_s'] for r in rows):.1f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = script_arguments(__doc__, "sample_screen", configs="40", seed="0", sample="1/16", screen="32x32")
    ap.add_argument("space", nargs="?", default=os.path.join(paths.REPO, "scripts", "examples", "explore_full.json"))
    a = ap.parse_args(argv)
    space = load_space(a.space)
    oprt = Oprt(paths.oprt_binary(a.oprt), space)
    rng = random.Random(int(a.seed))
    ratio = pixels(space.resolution) / pixels(a.screen)
    rows = []
    while len(rows) < int(a.configs):
        config = random_config(space, rng)
        folder = os.path.join(a.out, f"{len(rows):03d}")
        target, t_wall = price(oprt, space, config, os.path.join(folder, "target"), [])
        if target is None:
            continue
        sampled, s_wall = price(oprt, space, config, os.path.join(folder, "sample"), ["--sample", a.sample])
        screened, r_wall = price(oprt, space, config, os.path.join(folder, "screen"), [], resolution=a.screen)
        if sampled is None or screened is None:
            continue
        row = {"config": json.dumps(config, sort_keys=True), "target_wall_s": t_wall, "sample_wall_s": s_wall,
               "resolution_wall_s": r_wall}
        for fid, st, scale in (("target", target, 1.0), ("sample", sampled, 1.0), ("resolution", screened, ratio)):
            for obj, v in figures(st, scale).items():
                row[f"{fid}_{obj}"] = v
        row["sample_trusted"] = sampled["frames"][0]["sample"]["trusted"]
        rows.append(row)
    with open(os.path.join(a.out, "configs.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    text = report(rows, ("sample", "resolution"))
    with open(os.path.join(a.out, "summary.md"), "w") as f:
        f.write(text + "\n")
    print(text)
    return 0
