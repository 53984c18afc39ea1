"""A frame's figures per ray kind (primary, shadow, reflection, refraction) from stats.json.

stats.json gives per frame "rays" (primary and shadow always, reflection and refraction where
non-zero), "ray_kinds" (per kind: rays, fan-out, ray and answer bytes per ray, latency and spawn
delay; the GPP's starved cycles; rays by depth) and per unit the work counters of each kind. What
it does not give is the units' busy cycles per kind: `work_cycles` prices the counters with the
architecture's costs (the serial unit's: one operation at a time, docs/cycle-model.md), which
adds up to the units' busy cycles exactly when the unit is the serial one with ideal memory.
"""

#: The ray kinds in RayKind's order (model/geom/ray.h).
KINDS = ("primary", "shadow", "reflection", "refraction")
#: One letter per kind, for compact table cells ("P / S / R / T").
LETTERS = "PSRT"


def rays(frame):
    """{kind: rays of that kind in the frame} for every kind (0 where stats.json leaves it out)."""
    return {k: frame["rays"].get(k, 0) for k in KINDS}


def kind_figure(frame, key):
    """{kind: ray_kinds.kinds[kind][key]} for every kind, None where the frame has no ray of it."""
    kinds = frame["ray_kinds"]["kinds"]
    return {k: kinds[k][key] if k in kinds and kinds[k]["rays"] else None for k in KINDS}


def bus_bytes_per_ray(frame):
    """{kind: bytes on the bus per ray of that kind, the ray's own plus its answers}, None where
    the frame has no ray of the kind."""
    ray, answer = kind_figure(frame, "ray_bytes_per_ray"), kind_figure(frame, "answer_bytes_per_ray")
    return {k: None if ray[k] is None else ray[k] + answer[k] for k in KINDS}


def operation_cycles(arch):
    """The serial unit's cycles per counted operation, from stats.json's resolved "arch": a dict
    {counter: cycles} and the triangle test's cycles by exit stage (det, u, v, t)."""
    costs = arch["costs"]
    transform, triangle = costs["transform"], costs["triangle"]
    if arch.get("kernel") == "watertight":
        transform, triangle = costs["watertight"]["transform"], costs["watertight"]["triangle"]
    return ({"sphere_tests": costs["sphere"], "transforms": transform, "node_tests": costs["node"],
             "box_tests": costs["box"], "box_setups": costs["box_setup"]}, triangle)


def work_cycles(stats, frame):
    """{kind: busy cycles the frame's rays of that kind cost the units, summed over the units}:
    each unit's work counters of the kind priced by `operation_cycles`. Serial units only (a
    pipelined unit overlaps operations): ValueError otherwise."""
    model = stats["arch"].get("iu", {}).get("model", "serial")
    if model != "serial":
        raise ValueError(f"work_cycles: the units are '{model}': their cycles are not a sum of operations")
    per_op, triangle = operation_cycles(stats["arch"])
    out = dict.fromkeys(KINDS, 0)
    for unit in frame["ius"]:
        for kind, work in unit.get("work", {}).items():
            out[kind] += sum(work.get(op, 0) * c for op, c in per_op.items())
            out[kind] += sum(n * c for n, c in zip(work.get("triangle_exit_stage", ()), triangle))
    return out


def cells(values, fmt="{:,.0f}"):
    """A table cell of one value per kind, 'P / S / R / T' order, '-' where a value is None."""
    return " / ".join("-" if values[k] is None else fmt.format(values[k]) for k in KINDS)
