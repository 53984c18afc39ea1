"""Sweep specifications' parameter values (oprt-sweep/1, docs/sweeps.md): the parameters a
point may set, how each value is checked, and JSON files read with errors that name the file
and the place in it. Shared by scripts/sweep and scripts/explore."""
import json

from .values import is_integer

# Parameters a point may set: name -> (kind, constraint). Names of nested architecture fields are
# dotted ("bus.bytes_per_cycle"); choices are those of model/arch/arch.cpp. A number's range and
# syntax are oprt's own (base/numbers.h), checked by `oprt render --check` (check_points): the
# ranges below only document them, and no value is refused here for its size.
INT, NUMBER, CHOICE, TEXT = "integer", "number", "choice", "text"
PARAMS = {
    "frames": (TEXT, "frames"),
    "resolution": (TEXT, "resolution"),
    "ius": (INT, (1, 65536)),
    "level": (CHOICE, ("at", "lt", "analytic")),
    "quantum": (TEXT, "time"),
    "balance": (CHOICE, ("paper", "round_robin", "sa_n", "spatial", "feedback", "view")),
    "locality": (NUMBER, (0, 1)),
    "subdivide": (INT, (1, 4096)),
    "split": (CHOICE, ("count", "extent")),
    "accel": (CHOICE, ("brute", "bvh")),
    "kernel": (CHOICE, ("moller", "watertight")),
    "precision": (CHOICE, ("float", "double")),
    "clock_mhz": (NUMBER, (1e-3, 1e6)),
    "ray_fifo_depth": (INT, (0, 1 << 24)),
    "costs.sphere": (INT, (0, 1000000)),
    "costs.transform": (INT, (0, 1000000)),
    "costs.triangle": ("cycles4", (0, 1000000)),
    "costs.watertight.transform": (INT, (0, 1000000)),
    "costs.watertight.triangle": ("cycles4", (0, 1000000)),
    "costs.box": (INT, (0, 1000000)),
    "costs.box_setup": (INT, (0, 1000000)),
    "bus.model": (CHOICE, ("ideal", "shared")),
    "bus.bytes_per_cycle": (INT, (1, 1 << 20)),
    "bus.arbitration_cycles": (INT, (0, 1 << 20)),
    "bus.lt_arbitration": (CHOICE, ("sync", "calendar", "busy_until")),
    "memory.model": (CHOICE, ("ideal", "latency")),
    "memory.latency_cycles": (INT, (0, 1 << 20)),
    "memory.bytes_per_cycle": (INT, (1, 1 << 20)),
    "gpp.cycles_per_ray": (INT, (0, 1 << 20)),
    "gpp.cycles_per_hit": (INT, (0, 1 << 20)),
    "top": (CHOICE, ("flat", "bvh")),
    "costs.node": (INT, (0, 1000000)),
    "gpp.cycles_per_node": (INT, (0, 1 << 20)),
    "memory.sram_bytes": (INT, (0, 1 << 40)),
    "memory.cache.line_bytes": (INT, (16, 1 << 16)),
    "memory.cache.ways": (INT, (1, 1024)),
    "memory.cache.replacement": (CHOICE, ("lru", "fifo", "random")),
    "memory.cache.misses_outstanding": (INT, (1, 1024)),
    "memory.dram.latency_cycles": (INT, (0, 1 << 20)),
    "memory.dram.bytes_per_cycle": (INT, (1, 1 << 20)),
    "memory.dram.units_per_channel": (INT, (1, 65536)),
    "memory.dram.path": (CHOICE, ("channel", "bus")),
    "iu.model": (CHOICE, ("serial", "pipelined")),
    "iu.rays_in_flight": (INT, (1, 4096)),
    "iu.stack.depth": (INT, (1, 1024)),
    "iu.stack.overflow_cycles": (INT, (0, 1 << 20)),
    "iu.fp_latency.add": (INT, (1, 64)),
    "iu.fp_latency.multiply": (INT, (1, 64)),
    **{f"iu.{unit}.{kind}": (INT, (0, 1024)) for unit in ("node", "sphere", "transform", "box", "triangle")
       for kind in ("adders", "multipliers")},
    "tech": (TEXT, "file"),
}
# Architecture-file sections whose keys are parameters, "section.key" (nested: "iu.triangle.adders",
# "memory.cache.ways").
GROUPS = ("bus", "memory", "gpp", "costs", "iu")


class SpecError(Exception):
    """A bad SPEC: str() is 'FILE: /json/path: problem'."""

    def __init__(self, file, path, problem):
        super().__init__(f"{file}: {path or '/'}: {problem}")


def value_problem(name, value):
    """What is wrong with a parameter value's form (a number's size and syntax are oprt's to
    judge, check_points), or None."""
    kind, rule = PARAMS[name]
    if kind == INT:  # a count, or a byte count ("4G"): a JSON integer, or text for oprt to read
        if not (is_integer(value) or isinstance(value, str)):
            return f"expected an integer, found {json.dumps(value)}"
    elif kind == NUMBER:
        if not (is_integer(value) or isinstance(value, float)):
            return f"expected a number, found {json.dumps(value)}"
    elif kind == CHOICE:
        if value not in rule:
            return f"unknown value {json.dumps(value)} (expected one of: {', '.join(rule)})"
    elif kind == "cycles4":
        if not (isinstance(value, list) and len(value) == 4):
            return f"expected 4 cycle counts (exit stages det, u, v, t), found {json.dumps(value)}"
    elif not isinstance(value, str) or not value.strip():
        return f"expected {'a file name (relative to the SPEC)' if rule == 'file' else 'text'}, found {json.dumps(value)}"
    return None


def check_value(name, value, file, path):
    """Checks one parameter value (SpecError naming `path` if bad); returns it normalised
    (frames as text, as oprt takes it)."""
    if name == "frames" and is_integer(value):
        value = str(value)
    problem = value_problem(name, value)
    if problem:
        raise SpecError(file, path, f"{name}: {problem}")
    return value


def check_params(obj, file, path, what):
    if not isinstance(obj, dict):
        raise SpecError(file, path, f"expected an object of {what}")
    for name in obj:
        if name not in PARAMS:
            raise SpecError(file, f"{path}/{name}", f"unknown parameter (known: {', '.join(PARAMS)})")


def check_axes(obj, file, path):
    """A {parameter: [values]} object; returns it with checked values."""
    check_params(obj, file, path, "parameter: [values]")
    axes = {}
    for name, values in obj.items():
        if not isinstance(values, list):
            raise SpecError(file, f"{path}/{name}", f"expected a list of values, found {json.dumps(values)}")
        if not values:
            raise SpecError(file, f"{path}/{name}", "empty list of values: the grid would be empty")
        axes[name] = [check_value(name, v, file, f"{path}/{name}/{i}") for i, v in enumerate(values)]
        for i, v in enumerate(axes[name]):
            if v in axes[name][:i]:
                raise SpecError(file, f"{path}/{name}/{i}", f"value {json.dumps(v)} is listed twice")
    return axes


def flatten_arch(obj, file, prefix=""):
    """An oprt-arch/1 object -> {dotted parameter: value}; prefix is its JSON path in `file`."""
    flat = {}
    for key, value in obj.items():
        if key == "format" and value != "oprt-arch/1":
            raise SpecError(file, f"{prefix}/format", f'unsupported format {json.dumps(value)} (expected "oprt-arch/1")')
        if key in ("format", "comment"):
            continue
        if key in GROUPS and isinstance(value, dict):
            def walk(node, name, path):
                for sub, v in node.items():
                    if isinstance(v, dict):
                        walk(v, f"{name}.{sub}", f"{path}/{sub}")
                    elif f"{name}.{sub}" in PARAMS:
                        flat[f"{name}.{sub}"] = check_value(f"{name}.{sub}", v, file, f"{path}/{sub}")
                    else:
                        raise SpecError(file, f"{path}/{sub}", "unknown architecture key")
            walk(value, key, f"{prefix}/{key}")
        elif key in PARAMS and key not in ("frames", "resolution", "tech") and "." not in key:
            flat[key] = check_value(key, value, file, f"{prefix}/{key}")
        else:
            raise SpecError(file, f"{prefix}/{key}", "unknown architecture key")
    return flat


def read_json(file):
    try:
        with open(file) as f:
            return json.load(f)
    except OSError as e:
        raise SpecError(file, "", f"cannot read: {e.strerror}")
    except json.JSONDecodeError as e:
        raise SpecError(file, f"line {e.lineno}, column {e.colno}", f"not JSON: {e.msg}")


def read_document(file, fmt, keys, error=SpecError):
    """A JSON file that must be an object whose keys are among `keys` and whose "format" is fmt
    (a sweep SPEC, an explore space); raises error(file, path, problem) otherwise, SpecError
    when the file cannot be read or is not JSON."""
    doc = read_json(file)
    if not isinstance(doc, dict):
        raise error(file, "", "expected a JSON object")
    for key in doc:
        if key not in keys:
            raise error(file, f"/{key}", f"unknown key (known: {', '.join(keys)})")
    if doc.get("format") != fmt:
        raise error(file, "/format", f'expected "{fmt}", found {json.dumps(doc.get("format"))}')
    return doc
