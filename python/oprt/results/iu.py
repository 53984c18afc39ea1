"""Serial against pipelined intersection units, every combination (docs/results.md): for each
scene, unit model (serial, pipelined), acceleration inside spheres (brute, bvh), structure over
a unit's spheres (flat, bvh) and object memory (ideal: every unit holds its spheres; 16 KB and
64 KB per unit: a cache in front of DRAM where they do not fit), it runs

  oprt render SCENE --frames F --resolution R --level analytic --tech testbench/tech/45nm.json
       --iu IU --accel A --top T [--sram S]

(the paper's architecture otherwise: 32 units, one sphere per unit, ideal bus and GPP, unbounded
FIFOs; the analytic level is exact there) and prints one markdown row per run: makespan,
parallel efficiency, the pipelined units' utilisation per unit (issue slots / makespan, mean over
the IUs), the share of units whose memory is a cache, area and energy per frame. Every image
of a scene must be the same (checked).

  scripts/iu_results [--out DIR] [--oprt PATH] [--scenes room,polygons,kitchen]
"""
import os
import sys

from .. import paths
from ..render import render, script_arguments


SCENES = {
    "room": (os.path.join(paths.SCENES, "paper_room.json"), "0", "256x256"),
    "polygons": (os.path.join(paths.SCENES, "paper_polygons.json"), "0", "256x256"),
    "kitchen": (os.path.join(paths.SHARED, "bart", "kitchen", "kitchen.aff"), "0", "256x192"),
}
STAGES = ("node", "sphere", "transform", "box", "triangle")


def main(argv=None):
    ap = script_arguments(__doc__, "iu_results")
    ap.add_argument("--scenes", default="room,polygons,kitchen")
    a = ap.parse_args(argv)
    tech = os.path.join(paths.TECH, "45nm.json")
    print("| scene | IU | accel | top | memory | makespan (Mcycles) | efficiency | utilisation: node / sphere / "
          "transform / box / triangle | caches | area (mm2) | energy (mJ/frame) | vs serial |")
    print("|---|---|---|---|---|---:|---:|---|---:|---:|---:|---:|")
    for name in a.scenes.split(","):
        path, frames, res = SCENES[name]
        hashes = set()
        serial = {}
        for accel in ("brute", "bvh"):
            for top in ("flat", "bvh"):
                for sram in ("ideal", "16K", "64K"):
                    for iu in ("serial", "pipelined"):
                        args = [path, "--frames", frames, "--resolution", res, "--level", "analytic", "--tech", tech,
                                "--iu", iu, "--accel", accel, "--top", top]
                        if sram != "ideal":
                            args += ["--sram", sram]
                        s = render(args, os.path.join(a.out, name, f"{iu}_{accel}_{top}_{sram}"), a.oprt, "iu_results")
                        f = s["frames"][0]
                        hashes.add(f["image_hash"])
                        units = f["ius"]
                        util = "-"
                        if iu == "pipelined":
                            parts = []
                            for st in STAGES:
                                busy = [u["pipeline"]["stages"][st]["busy"] for u in units if st in u["pipeline"]["stages"]]
                                parts.append(f"{100 * sum(busy) / (len(units) * f['makespan_cycles']):.0f}%" if busy else "-")
                            util = " / ".join(parts)
                        key = (accel, top, sram)
                        if iu == "serial":
                            serial[key] = f["makespan_cycles"]
                        caches = sum(1 for u in units if u["memory"]["cache"])
                        print(f"| {name} | {iu} | {accel} | {top} | {sram} | {f['makespan_cycles'] / 1e6:,.3f} | "
                              f"{f['parallel_efficiency']:.3f} | {util} | {caches} of {len(units)} | "
                              f"{s['area_mm2']['total']:.2f} | {f['energy_j']['total'] * 1e3:.3f} | "
                              f"{serial[key] / f['makespan_cycles']:.1f}x |", flush=True)
        if len(hashes) != 1:
            sys.exit(f"iu_results: {name}: the images differ between configurations: {sorted(hashes)}")
    return 0

