"""Regression figures of the timed model: run small fixed configurations and compare their
makespan, per-unit cycles, ray counts and image hashes with the checked-in golden file; where
object memories are caches, every unit's line hits and misses too (a change of replacement
policy or line lookup changes them).

  scripts/golden list
  scripts/golden check [NAME ...]   exit 1 and print the differences if any figure changed
  scripts/golden bless [NAME ...]   rerun, print what changed, and rewrite the golden file

Configurations: tests/golden/configs.json; figures: tests/golden/golden.json. A configuration
with "same_as": OTHER has no figures of its own: it must give exactly OTHER's (a different
path to the same timing, e.g. memory.dram.path "external" bound to oprt's own DRAM model).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from .. import paths

CONFIGS = os.path.join(paths.REPO, "tests", "golden", "configs.json")
GOLDEN = os.path.join(paths.REPO, "tests", "golden", "golden.json")


def figures(stats):
    """The pinned figures of one run: per frame, everything that must not drift."""
    out = []
    for f in stats["frames"]:
        caches = any(u["memory"]["cache"] for u in f["ius"])
        out.append({
            "frame": f["frame"],
            "makespan_cycles": f["makespan_cycles"],
            "rays": f["rays"],
            "image_hash": f["image_hash"],
            "bus_busy_cycles": f["bus"]["busy_cycles"],
            "ius": [[u["cycles"][k] for k in ("sphere", "transform", "primitive", "stall", "idle")]
                    for u in f["ius"]],
        })
        if caches:
            out[-1]["memory"] = [[u["memory"]["hits"], u["memory"]["misses"]] for u in f["ius"]]
    return out


def run(name, config, oprt):
    with tempfile.TemporaryDirectory(prefix="oprt_golden_") as tmp:
        arch = os.path.join(tmp, "arch.json")
        with open(arch, "w") as f:
            json.dump(config["arch"], f)
        cmd = [oprt, "render", os.path.join(paths.REPO, config["scene"]), "--arch", arch,
               "--frames", config["frames"], "--resolution", config["resolution"],
               "--out", os.path.join(tmp, "out"), "--no-progress"]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"golden: {name}: oprt failed ({r.returncode}):\n{r.stdout}{r.stderr}")
        with open(os.path.join(tmp, "out", "stats.json")) as f:
            return figures(json.load(f))


def differences(old, new):
    """Human-readable lines for every figure that changed."""
    lines = []
    if old is None:
        return ["  (new configuration)"]
    for fo, fn in zip(old, new):
        tag = f"  frame {fn['frame']}"
        for key in ("makespan_cycles", "image_hash", "bus_busy_cycles", "rays"):
            if fo[key] != fn[key]:
                lines.append(f"{tag}: {key} {fo[key]} -> {fn[key]}")
        for u, (a, b) in enumerate(zip(fo["ius"], fn["ius"])):
            for k, x, y in zip(("sphere", "transform", "primitive", "stall", "idle"), a, b):
                if x != y:
                    lines.append(f"{tag}: iu {u} {k} {x} -> {y} ({(y - x) / max(x, 1):+.2%})")
        for u, (a, b) in enumerate(zip(fo.get("memory", []), fn.get("memory", []))):
            for k, x, y in zip(("hits", "misses"), a, b):
                if x != y:
                    lines.append(f"{tag}: memory {u} {k} {x} -> {y}")
        if ("memory" in fo) != ("memory" in fn):
            lines.append(f"{tag}: cache figures {'memory' in fo} -> {'memory' in fn}")
        if len(fo["ius"]) != len(fn["ius"]):
            lines.append(f"{tag}: units {len(fo['ius'])} -> {len(fn['ius'])}")
    if len(old) != len(new):
        lines.append(f"  frames {len(old)} -> {len(new)}")
    return lines


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("command", choices=["list", "check", "bless"])
    p.add_argument("names", nargs="*")
    p.add_argument("--oprt", default=paths.oprt_binary())
    a = p.parse_args(argv)
    with open(CONFIGS) as f:
        configs = json.load(f)["configs"]
    golden = {}
    if os.path.exists(GOLDEN):
        with open(GOLDEN) as f:
            golden = json.load(f)
    names = a.names or sorted(configs)
    unknown = [n for n in names if n not in configs]
    if unknown:
        sys.exit(f"golden: unknown configuration(s): {', '.join(unknown)} (see {CONFIGS})")
    if a.command == "list":
        print("\n".join(names))
        return 0
    failed = 0
    for name in names:
        new = run(name, configs[name], a.oprt)
        same_as = configs[name].get("same_as")
        diff = differences(golden.get(same_as or name), new)
        if same_as:
            name = f"{name} (same as {same_as})"
        if a.command == "check":
            if diff:
                failed += 1
                print(f"{name}: CHANGED\n" + "\n".join(diff))
            else:
                print(f"{name}: ok ({len(new)} frames)")
        else:
            if same_as:  # never blessed on its own: a difference is a fault
                failed += bool(diff)
                print(f"{name}: " + ("equal" if not diff else "DIFFERENT\n" + "\n".join(diff)))
                continue
            print(f"{name}: " + ("unchanged" if not diff else "updated\n" + "\n".join(diff)))
            golden[name] = new
    if a.command == "bless":
        with open(GOLDEN + ".tmp", "w") as f:
            json.dump(golden, f, indent=1, sort_keys=True)
            f.write("\n")
        os.replace(GOLDEN + ".tmp", GOLDEN)
    return 1 if failed else 0

