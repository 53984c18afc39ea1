"""A sweep's results: OUT/aggregate.csv (a row per finished point and frame), OUT/status.csv
(every point) and OUT/summary.md (the table it prints)."""
import csv
import json
import os
import sys

from ..files import write_atomically
from .points import label
from .run import is_done

ARCH_COLUMNS = ["ius", "balance", "subdivide", "split", "level", "quantum_ns", "accel", "kernel", "precision",
                "ray_fifo_depth", "bus.model", "bus.bytes_per_cycle", "bus.arbitration_cycles", "memory.model",
                "memory.latency_cycles", "memory.bytes_per_cycle", "gpp.cycles_per_ray", "gpp.cycles_per_hit",
                "clock_mhz", "costs.sphere", "costs.transform", "costs.triangle",
                "iu.model", "iu.rays_in_flight", "iu.stack.depth", "iu.fp_latency.add", "iu.fp_latency.multiply"]
# The IU's arithmetic as the run resolved it (adders and multipliers per unit, all stages; the
# triangle unit's initiation interval: 0 for the serial IU) and the technology table.
FIGURE_COLUMNS = ["frame", "units", "spheres", "makespan_cycles", "makespan_us", "parallel_efficiency",
                  "idle_fraction", "busy_cycles", "unit_busy_min", "unit_busy_max", "stall_cycles",
                  "bus_busy_cycles", "bus_busy_fraction", "bus_bytes", "rays_primary", "rays_shadow",
                  "wall_s", "rays_per_wall_s", "image_hash",
                  "iu.adders", "iu.multipliers", "iu.triangle_ii", "tech", "frame_time_s", "energy_j", "area_mm2"]
# --top and --sram (after the others, so that their positions stay): the architecture, then per
# frame summed over the units their memory's line hits and misses (caches only), the hit rate,
# bytes from DRAM, the cycles they waited for object memory, node-test cycles, the GPP's refit.
TOP_MEMORY_ARCH = ["top", "memory.sram_bytes", "memory.cache.line_bytes", "memory.cache.ways",
                   "memory.cache.replacement", "memory.cache.misses_outstanding", "memory.dram.latency_cycles",
                   "memory.dram.bytes_per_cycle", "memory.dram.units_per_channel", "memory.dram.path"]
TOP_MEMORY_FIGURES = ["cache_units", "memory_hits", "memory_misses", "memory_hit_rate", "dram_bytes",
                      "memory_stall_cycles", "node_cycles", "gpp_refit_cycles"]
# Whitted's recursion (issue 29, after the others): the depth bound the run used and the
# secondary rays per frame (0 where the scene reflects and transmits nothing).
RAY_KIND_COLUMNS = ["gpp.depth", "rays_reflection", "rays_refraction"]
COLUMNS = ["point", "dir", "scene", "frames", "resolution"] + ARCH_COLUMNS + FIGURE_COLUMNS + TOP_MEMORY_ARCH + \
    TOP_MEMORY_FIGURES + RAY_KIND_COLUMNS


def memory_figures(fr):
    """The --top / --sram figures of one frame (empty where the model that wrote it had none)."""
    mem = [u["memory"] for u in fr["ius"] if "memory" in u]
    if not mem:
        return {c: "" for c in TOP_MEMORY_FIGURES}
    hits, misses = sum(m["hits"] for m in mem), sum(m["misses"] for m in mem)
    return {"cache_units": sum(1 for m in mem if m["cache"]), "memory_hits": hits, "memory_misses": misses,
            "memory_hit_rate": round(hits / (hits + misses), 6) if hits + misses else "",
            "dram_bytes": sum(m["dram_bytes"] for m in mem), "memory_stall_cycles": sum(m["stall_cycles"] for m in mem),
            "node_cycles": sum(u["cycles"].get("node", 0) for u in fr["ius"]),
            "gpp_refit_cycles": fr.get("gpp", {}).get("refit_cycles", 0)}


def rows_of(out, index, point):
    """The aggregate rows (one per frame) of a finished point, from its stats.json."""
    with open(os.path.join(out, "points", point["dir"], "stats.json")) as f:
        stats = json.load(f)
    arch = stats["arch"]
    flat = {k: arch[k] for k in arch if not isinstance(arch[k], dict)}
    flat.update({f"{g}.{k}": v for g in ("bus", "memory", "gpp", "costs") for k, v in arch[g].items()})
    for g in ("cache", "dram"):
        flat.update({f"memory.{g}.{k}": v for k, v in arch["memory"].get(g, {}).items()})
    flat["costs.triangle"] = "-".join(map(str, arch["costs"]["triangle"]))
    iu = arch.get("iu", {})
    flat.update({f"iu.{k}": iu.get(k, "") for k in ("model", "rays_in_flight")})
    flat["iu.stack.depth"] = iu.get("stack", {}).get("depth", "")
    flat.update({f"iu.fp_latency.{k}": iu.get("fp_latency", {}).get(k, "") for k in ("add", "multiply")})
    arithmetic = stats.get("iu_arithmetic", {})
    cost = {"iu.adders": arithmetic.get("adders", ""), "iu.multipliers": arithmetic.get("multipliers", ""),
            "iu.triangle_ii": stats.get("iu_stages", {}).get("triangle", {}).get("ii", 0 if arithmetic else ""),
            "tech": stats.get("tech", {}).get("file", ""), "area_mm2": stats.get("area_mm2", {}).get("total", "")}
    rows = []
    for fr in stats["frames"]:
        busy = [u["busy_cycles"] for u in fr["ius"]]
        makespan = fr["makespan_cycles"]
        rows.append({
            "point": index, "dir": os.path.join("points", point["dir"]), "scene": point["params"]["scene"],
            "frames": point["params"].get("frames", "all"), "resolution": "x".join(map(str, stats["resolution"])),
            **{c: flat.get(c, "") for c in ARCH_COLUMNS},  # "split": absent from stats before issue 15
            "frame": fr["frame"], "units": stats["units"], "spheres": stats["spheres"], "makespan_cycles": makespan,
            "makespan_us": round(makespan / arch["clock_mhz"], 3),
            "parallel_efficiency": round(fr["parallel_efficiency"], 6), "idle_fraction": round(fr["idle_fraction"], 6),
            "busy_cycles": fr["busy_cycles"], "unit_busy_min": min(busy), "unit_busy_max": max(busy),
            "stall_cycles": sum(u["cycles"]["stall"] for u in fr["ius"]),
            "bus_busy_cycles": fr["bus"]["busy_cycles"],
            "bus_busy_fraction": round(fr["bus"]["busy_cycles"] / makespan, 6) if makespan else 0,
            "bus_bytes": fr["bus"]["bytes"], "rays_primary": fr["rays"]["primary"], "rays_shadow": fr["rays"]["shadow"],
            "wall_s": round(fr["wall_s"], 4), "rays_per_wall_s": round(fr["rays_per_wall_s"]),
            "image_hash": fr.get("image_hash", ""), **cost,
            "frame_time_s": fr.get("frame_time_s", ""), "energy_j": fr.get("energy_j", {}).get("total", ""),
            **{c: flat.get(c, "") for c in TOP_MEMORY_ARCH}, **memory_figures(fr),
            "gpp.depth": flat.get("gpp.depth", ""), "rays_reflection": fr["rays"].get("reflection", 0),
            "rays_refraction": fr["rays"].get("refraction", 0)})
    return rows


def aggregate(out, points, names):
    """Writes OUT/aggregate.csv (finished points only), OUT/status.csv (every point), OUT/summary.md,
    prints the summary table; returns the indices of points not done."""
    rows, status, table, missing = [], [], [], []
    for i, p in enumerate(points):
        d = os.path.join(out, "points", p["dir"])
        state = "done" if is_done(out, p) else "failed" if os.path.isfile(os.path.join(d, "failed.json")) else "not run"
        exit_status = ""
        if state == "failed":
            with open(os.path.join(d, "failed.json")) as f:
                failure = json.load(f)
            exit_status = failure["exit_status"]
            why = (failure.get("log_tail", "").strip().splitlines() or ["no output"])[-1]
            print(f"sweep: point {i} failed (exit status {exit_status}): {why}", file=sys.stderr)
        status.append({"point": i, "dir": os.path.join("points", p["dir"]), "status": state, "exit_status": exit_status,
                       "where": p["where"], "params": json.dumps(p["params"], sort_keys=True)})
        if state != "done":
            missing.append(i)
            table.append([str(i), label(p, names), state.upper() + (f" ({exit_status})" if exit_status != "" else "")]
                         + [""] * 9)
            continue
        mine = rows_of(out, i, p)
        rows += mine
        n = len(mine)
        table.append([str(i), label(p, names), str(mine[0]["units"]),
                      f"{sum(r['makespan_cycles'] for r in mine) / 1e6:.3f}",
                      f"{sum(r['parallel_efficiency'] for r in mine) / n:.3f}",
                      f"{sum(r['idle_fraction'] for r in mine) / n:.3f}",
                      f"{max(r['unit_busy_max'] / max(r['unit_busy_min'], 1) for r in mine):.1f}",
                      f"{sum(r['bus_busy_fraction'] for r in mine) / n:.3f}",
                      f"{sum(r['frame_time_s'] for r in mine) / n * 1e3:.3f}" if mine[0]["frame_time_s"] != "" else "",
                      f"{sum(r['energy_j'] for r in mine) / n * 1e3:.3f}" if mine[0]["energy_j"] != "" else "",
                      f"{mine[0]['area_mm2']:.2f}" if mine[0]["area_mm2"] != "" else "",
                      f"{sum(r['wall_s'] for r in mine):.2f}"])
    for name, fields, data in (("aggregate.csv", COLUMNS, rows),
                               ("status.csv", ["point", "dir", "status", "exit_status", "where", "params"], status)):
        def write(f, fields=fields, data=data):
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(data)
        write_atomically(os.path.join(out, name), write)

    head = ["#", "point (" + " ".join(names) + ")" if names else "point", "units", "makespan Mcyc",
            "efficiency", "idle", "busy max/min", "bus busy", "frame ms", "energy mJ", "area mm2", "wall s"]
    widths = [max(len(r[c]) for r in table + [head]) for c in range(len(head))]
    line = lambda r: "  ".join(v.ljust(w) if c == 1 else v.rjust(w) for c, (v, w) in enumerate(zip(r, widths)))
    print(line(head))
    for r in table:
        print(line(r))
    write_atomically(os.path.join(out, "summary.md"), lambda f: f.write(
        "| " + " | ".join(head) + " |\n|" + "|".join("---" if c == 1 else "---:" for c in range(len(head))) + "|\n"
        + "".join("| " + " | ".join(r) + " |\n" for r in table)))
    done = len(points) - len(missing)
    print(f"sweep: {done} of {len(points)} points done; aggregate in {os.path.join(out, 'aggregate.csv')}"
          + (f"; not done: {', '.join(map(str, missing))} (see status.csv)" if missing else ""), file=sys.stderr)
    return missing

