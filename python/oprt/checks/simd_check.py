"""Render with the SIMD kernels and with the scalar ones; every output must be the same.

  scripts/simd_check [--oprt PATH] [--out DIR] [--quick] [--kitchen PATH]
  scripts/simd_check --speed N [--oprt PATH] [--out DIR] [SCENE]

Renders frame 0 of both paper scenes (scenes/paper_room.json, scenes/paper_polygons.json, at
their 256x256) and of BART's kitchen (/work/shared/bart/kitchen/kitchen.aff, at 64x64) once
with OPRT_SIMD=off (the scalar kernels) and once with OPRT_SIMD=on (geom/simd_kernels.h), in
these configurations:
  reference                  oprt reference (Moller-Trumbore, float, brute force)
  reference watertight       --kernel watertight
  reference double           --precision double
  reference double wt        --precision double --kernel watertight
  reference bvh              --accel bvh
  render paper               oprt render --arch testbench/arch/paper.json (the timed model)
  render contended           --arch testbench/arch/contended.json (the memory model reads the
                             exit-stage log)
and compares every file each run writes: images byte for byte, JSON after dropping the fields
that measure wall time (wall_s, rays_per_wall_s, rays_per_s, build_s), everything else byte
for byte. --quick: paper scenes at 64x64, no double configurations. Prints a table with each
run's wall seconds (off, on) and the verdict.

First it disassembles oprt (objdump) and checks the functions that hold the kernels (the
block loops nearest_simd / any_simd / nearest_loop / any_loop, sphere_hits, the scalar
kernels, and whatever inlined them: trace_nearest, trace_any, the block and BVH functions):
no fused multiply-add on packed
floats or doubles, nor on scalar floats, may appear. Scalar double ones (...sd) are allowed:
the watertight kernel's exact fallback in double (detail::exact_cross) uses std::fma on
purpose, to get a product's rounding error, and it is the only std::fma in model/. Fused
multiply-adds anywhere else in oprt are listed as a note (GCC 12's SLP vectorizer emits
vfmaddsub for some mul/add pairs despite -ffp-contract=off).

--speed N: instead, the single-thread speed of the reference renderer: `oprt reference SCENE
--frames 0` (default scenes/paper_polygons.json) N times with OPRT_SIMD=off and N times with
on, interleaved; prints per mode the frame's wall time (frames[0].wall_s, min and median) and
triangle tests per wall second (the sum of work.*.triangle_tests over wall_s). Wall times are
disturbed by other work on the machine: the min is the least disturbed.

Exit status: 0 all identical, 1 a difference or a failed run, 2 bad command line.
"""
import argparse
import json
import os
import subprocess
import sys
import time

from .. import paths

KERNEL_FUNCTIONS = ("nearest_simd", "any_simd", "nearest_chunks", "any_chunks", "sphere_hits", "nearest_loop", "any_loop",
                    "intersect_moller", "intersect_watertight", "hit_sphere", "trace_nearest", "trace_any",
                    "nearest_in_block", "any_in_block", "nearest_in_bvh", "any_in_bvh")
WALL_FIELDS = {"wall_s", "rays_per_wall_s", "rays_per_s", "build_s"}

CONFIGS = [
    ("reference", ["reference"], True),
    ("reference watertight", ["reference", "--kernel", "watertight"], True),
    ("reference double", ["reference", "--precision", "double"], False),
    ("reference double wt", ["reference", "--precision", "double", "--kernel", "watertight"], False),
    ("reference bvh", ["reference", "--accel", "bvh"], True),
    ("render paper", ["render", "--arch", os.path.join(paths.REPO, "testbench/arch/paper.json"), "--no-progress"], True),
    ("render contended", ["render", "--arch", os.path.join(paths.REPO, "testbench/arch/contended.json"), "--no-progress"],
     True),
]


def strip_wall(x):
    if isinstance(x, dict):
        return {k: strip_wall(v) for k, v in x.items() if k not in WALL_FIELDS}
    if isinstance(x, list):
        return [strip_wall(v) for v in x]
    return x


def run(oprt, args, out, mode):
    env = dict(os.environ, OPRT_SIMD=mode, SYSTEMC_DISABLE_COPYRIGHT_MESSAGE="1")
    os.makedirs(out, exist_ok=True)
    start = time.monotonic()
    p = subprocess.run([oprt] + args + ["--out", out], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True)
    wall = time.monotonic() - start
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(args)} (OPRT_SIMD={mode}) failed with status {p.returncode}:\n{p.stdout}")
    return wall


def differences(a, b):
    """The files of directory a that differ from b's, or that only one of them has."""
    fa, fb = sorted(os.listdir(a)), sorted(os.listdir(b))
    diff = [f"only in one: {f}" for f in sorted(set(fa) ^ set(fb))]
    for f in sorted(set(fa) & set(fb)):
        pa, pb = os.path.join(a, f), os.path.join(b, f)
        if f.endswith(".json"):
            with open(pa) as x, open(pb) as y:
                if strip_wall(json.load(x)) != strip_wall(json.load(y)):
                    diff.append(f)
        else:
            with open(pa, "rb") as x, open(pb, "rb") as y:
                if x.read() != y.read():
                    diff.append(f)
    return diff, len(set(fa) & set(fb))


def fma_check(oprt):
    """(kernel functions seen, offending lines, other functions with FMAs) for oprt's disassembly."""
    dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", oprt], stdout=subprocess.PIPE, text=True,
                         check=True).stdout
    fn, kernels, bad, elsewhere = "", set(), [], set()
    for line in dis.splitlines():
        if line.endswith(">:") and " <" in line:
            fn = line.split(" <", 1)[1][:-2]
            continue
        parts = line.split("\t")
        insn = parts[1].split()[0] if len(parts) > 1 and parts[1].split() else ""
        fused = insn.startswith("vfm") or insn.startswith("vfnm")
        if not any(k in fn for k in KERNEL_FUNCTIONS):
            if fused and "exact_cross" not in fn:
                elsewhere.add(fn)
            continue
        kernels.add(fn)
        if fused and not insn.endswith("sd"):
            bad.append(f"{fn}: {insn}")
    return len(kernels), bad, sorted(elsewhere)


def speed(oprt, out, scene, reps):
    rows = {"off": [], "on": []}
    for _ in range(reps):
        for mode in rows:
            d = os.path.join(out, "speed", mode)
            run(oprt, ["reference", scene, "--frames", "0"], d, mode)
            with open(os.path.join(d, "reference.json")) as f:
                frame = json.load(f)["frames"][0]
            tests = sum(w["triangle_tests"] for w in frame["work"].values())
            rows[mode].append((frame["wall_s"], tests))
    print(f"{os.path.basename(scene)}, frame 0, {reps} runs per mode")
    print(f"{'OPRT_SIMD':<10} {'triangle tests':>15} {'wall_s min':>11} {'median':>8} {'M tests/s (min)':>16} {'(median)':>9}")
    for mode, v in rows.items():
        walls = sorted(w for w, _ in v)
        med = walls[len(walls) // 2] if len(walls) % 2 else 0.5 * (walls[len(walls) // 2 - 1] + walls[len(walls) // 2])
        tests = v[0][1]
        print(f"{mode:<10} {tests:>15} {walls[0]:>11.3f} {med:>8.3f} {tests / walls[0] / 1e6:>16.0f} {tests / med / 1e6:>9.0f}")
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--oprt", default=os.path.join(paths.REPO, "build/testbench/oprt"))
    ap.add_argument("--out", default=os.path.join(paths.REPO, "out/simd_check"))
    ap.add_argument("--kitchen", default=os.path.join(paths.REPO, "../shared/bart/kitchen/kitchen.aff"))
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--speed", type=int, metavar="N")
    ap.add_argument("scene", nargs="?", default=os.path.join(paths.REPO, "scenes/paper_polygons.json"))
    a = ap.parse_args(argv)
    if not os.access(a.oprt, os.X_OK):
        print(f"simd_check: {a.oprt}: no oprt binary (scripts/build, or --oprt)", file=sys.stderr)
        return 2
    if a.speed is not None:
        if a.speed < 1 or not os.path.exists(a.scene):
            print("simd_check: --speed N needs N >= 1 and an existing scene", file=sys.stderr)
            return 2
        try:
            return speed(a.oprt, a.out, a.scene, a.speed)
        except RuntimeError as e:
            print(e, file=sys.stderr)
            return 1
    paper_res = ["--resolution", "64x64"] if a.quick else []
    scenes = [("paper_room", os.path.join(paths.REPO, "scenes/paper_room.json"), paper_res),
              ("paper_polygons", os.path.join(paths.REPO, "scenes/paper_polygons.json"), paper_res),
              ("kitchen", a.kitchen, ["--resolution", "64x64"])]
    failed = 0
    n, bad, elsewhere = fma_check(a.oprt)
    print(f"fused multiply-adds in the {n} kernel functions: "
          + ("none (scalar double ones, exact_cross's, allowed)" if not bad else f"{len(bad)} FOUND"))
    for b in bad[:20]:
        print("  " + b)
    failed += bool(bad)
    # Not the kernels' business, but the same guarantee (-ffp-contract=off): reported, not failed.
    if elsewhere:
        print(f"note: fused multiply-adds outside the kernels, in {len(elsewhere)} function(s): " + "; ".join(elsewhere))
    print(f"{'scene':<16} {'configuration':<22} {'off s':>7} {'on s':>7}  files  result")
    for name, path, res in scenes:
        if not os.path.exists(path):
            print(f"simd_check: {path}: no such scene", file=sys.stderr)
            return 2
        for label, args, in_quick in CONFIGS:
            if a.quick and not in_quick:
                continue
            cmd = args[:1] + [path, "--frames", "0"] + res + args[1:]
            base = os.path.join(a.out, name, label.replace(" ", "_"))
            try:
                t_off = run(a.oprt, cmd, os.path.join(base, "off"), "off")
                t_on = run(a.oprt, cmd, os.path.join(base, "on"), "on")
            except RuntimeError as e:
                print(e, file=sys.stderr)
                failed += 1
                continue
            diff, n = differences(os.path.join(base, "off"), os.path.join(base, "on"))
            verdict = "identical" if not diff else "DIFFERENT: " + ", ".join(diff)
            failed += bool(diff)
            print(f"{name:<16} {label:<22} {t_off:7.2f} {t_on:7.2f}  {n:5d}  {verdict}", flush=True)
    print("all identical" if not failed else f"{failed} run(s) differ or failed")
    return 1 if failed else 0

