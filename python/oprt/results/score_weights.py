"""Score static per-sphere weights against the cycles a run measured, without rerunning it.

  scripts/score_weights STATS.json [--units N]

STATS.json: an `oprt render` run (any policy) whose stats hold, per frame, the measured cycles
of every sphere (`sphere_cycles`) and, per sphere, its SA x N and the model's sa_n estimate
(`sphere_list`). For each set of weights below, the longest-processing-time greedy of
model/balance/assign.cpp (decreasing weight, ties by lower sphere; least-loaded unit, ties by
lower unit) assigns the spheres to the units; each frame is then scored with the measured
cycles: efficiency = sum of cycles / (units x the busiest unit's cycles). Under the ideal
architecture a unit's busy cycles are the sum of its spheres' cycles, so this is the run's
efficiency whenever the busiest unit sets the makespan (rows marked "run" can be checked
against real runs). Weights scored:
  sa_n estimate   the model's sa_n weights (what --balance sa_n runs on)
  plain SA x N    the paper's surface area x primitive count
  frame 0 cycles  the measured cycles of the first frame, kept for every frame: the best any
                  static assignment built from one frame can do on this animation
"""
import argparse
import json
import sys


def lpt(weights, units):
    order = sorted(range(len(weights)), key=lambda s: (-weights[s], s))
    load = [0.0] * units
    owner = [0] * len(weights)
    for s in order:
        u = min(range(units), key=lambda i: (load[i], i))
        owner[s] = u
        load[u] += weights[s]
    return owner


def efficiency(owner, cycles, units):
    load = [0] * units
    for s, c in enumerate(cycles):
        load[owner[s]] += c
    return sum(load) / (units * max(load))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("stats")
    ap.add_argument("--units", type=int, help="units to assign to (default: the run's)")
    a = ap.parse_args(argv)
    try:
        with open(a.stats) as f:
            stats = json.load(f)
        spheres = stats["sphere_list"]
        frames = stats["frames"]
        cycles = [fr["sphere_cycles"] for fr in frames]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"score_weights: {a.stats}: {e}")
    units = a.units or stats["units"]
    weights = {"sa_n estimate": [s["sa_n_weight"] for s in spheres],
               "plain SA x N": [s["sa_n"] for s in spheres],
               "frame 0 cycles": cycles[0]}
    print(f"| weights ({len(spheres)} spheres, {units} units, {len(frames)} frames) | mean efficiency | min | max |")
    print("|---|---:|---:|---:|")
    for name, w in weights.items():
        owner = lpt(w, units)
        e = [efficiency(owner, c, units) for c in cycles]
        print(f"| {name} | {sum(e) / len(e):.3f} | {min(e):.3f} | {max(e):.3f} |")

