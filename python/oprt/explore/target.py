"""How well does the search do against the exhaustive grid? (docs/explore.md)

  scripts/explore_target SPACE.json --out DIR [--fraction 0.2] [--seeds 0,1,2] [--sampler nsga2|tpe]
                         [--jobs N] [--oprt BINARY] [--target 0.95]

Evaluates every point of SPACE (scripts/explore --grid, into DIR/grid), then runs the search
once per seed with `fraction` of the grid's evaluations (DIR/<sampler>-seed<S>), each taking the
figures of the configurations it proposes from the grid (`--price-from`: the model is deterministic,
so this is what running oprt again would give, without the time). Prints, and writes into
DIR/target.md, each search's hypervolume against the grid's (the same reference point: the
space's) and their median. Exit status 0 when the median reaches --target, 1 when not, 2 on bad
input. Resumable like scripts/explore (each folder is one).
"""
import argparse
import json
import os
import re
import subprocess
import sys


def explore_command():
    """The explore command beside this one: scripts/explore beside scripts/explore_target, or an
    installed oprt-explore beside oprt-explore-target."""
    return re.sub(r"[-_]target$", "", os.path.abspath(sys.argv[0]))


def run(explore, args, what):
    print(f"explore_target: {what}: {' '.join(args[1:])}", file=sys.stderr, flush=True)
    r = subprocess.run([sys.executable, explore] + args[1:], stdout=subprocess.DEVNULL)
    return r.returncode


def result(folder):
    with open(os.path.join(folder, "result.json")) as f:
        return json.load(f)


def main(argv=None, explore=None):
    """scripts/explore_target; `explore`: the explore command to run (default: explore_command()).
    Returns the exit status."""
    explore = explore or explore_command()
    ap = argparse.ArgumentParser(prog="explore_target", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("space", metavar="SPACE.json")
    ap.add_argument("--out", required=True, help="folder for the grid and the searches")
    ap.add_argument("--fraction", type=float, default=0.2, help="the searches' evaluations, as a fraction of the grid's")
    ap.add_argument("--seeds", default="0,1,2", help="comma-separated seeds (default 0,1,2)")
    ap.add_argument("--sampler", choices=("nsga2", "tpe", "portfolio"), default="nsga2")
    ap.add_argument("--jobs", "-j", type=int, default=len(os.sched_getaffinity(0)), help="the grid's evaluations at once")
    ap.add_argument("--oprt", help="the oprt binary (as scripts/explore)")
    ap.add_argument("--target", type=float, default=0.95, help="the median ratio to reach (default 0.95)")
    a = ap.parse_args(argv)
    try:
        seeds = [int(s) for s in a.seeds.split(",")]
    except ValueError:
        ap.error(f"--seeds {a.seeds}: expected integers separated by commas")
    if not 0 < a.fraction <= 1:
        ap.error("--fraction must be in (0, 1]")
    common = ["--oprt", a.oprt] if a.oprt else []
    grid = os.path.join(a.out, "grid")
    os.makedirs(a.out, exist_ok=True)
    rc = run(explore, ["explore", a.space, "--out", grid, "--grid", "--no-confirm", "--jobs", str(a.jobs)] + common, "the grid")
    if rc != 0:
        print(f"explore_target: the grid failed (exit status {rc}); see {grid}", file=sys.stderr)
        return 2 if rc == 2 else 1
    g = result(grid)
    n = max(1, round(a.fraction * g["evaluations"]))
    rows = []
    for seed in seeds:
        folder = os.path.join(a.out, f"{a.sampler}-seed{seed}")
        rc = run(explore, ["explore", a.space, "--out", folder, "--evaluations", str(n), "--seed", str(seed), "--sampler",
                  a.sampler, "--price-from", grid, "--screen", "none", "--no-confirm", "--jobs", "1"] + common, f"search, seed {seed}")
        if rc != 0:
            print(f"explore_target: the search with seed {seed} failed (exit status {rc}); see {folder}", file=sys.stderr)
            return 2 if rc == 2 else 1
        r = result(folder)
        rows.append((seed, r["evaluations"], r["hypervolume"], r["hypervolume"] / g["hypervolume"] if g["hypervolume"] else 0.0))
    ratios = sorted(row[3] for row in rows)
    median = ratios[len(ratios) // 2] if len(ratios) % 2 else (ratios[len(ratios) // 2 - 1] + ratios[len(ratios) // 2]) / 2
    met = median >= a.target
    lines = [f"Search against the exhaustive grid: {os.path.basename(a.space)}, {a.sampler}, "
             f"{n} evaluations ({a.fraction:.0%} of the grid's {g['evaluations']})", "",
             "| run | evaluations | hypervolume | of the grid's |", "|---|---:|---:|---:|",
             f"| grid | {g['evaluations']} | {g['hypervolume']:.5f} | 100 % |"]
    lines += [f"| seed {s} | {e} | {h:.5f} | {q * 100:.1f} % |" for s, e, h, q in rows]
    lines += ["", f"Median over {len(rows)} seeds: **{median * 100:.1f} %** of the grid's hypervolume "
                  f"(target {a.target * 100:.0f} %: {'met' if met else 'NOT met'})."]
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(a.out, "target.md"), "w") as f:
        f.write(text)
    return 0 if met else 1

