"""A sweep's points: its SPEC (oprt-sweep/1, docs/sweeps.md) read, checked and expanded into
points, each with its parameters, scene file, place in the SPEC and directory name."""
import hashlib
import itertools
import json
import os

from ..spec import SpecError, check_axes, check_params, check_value, flatten_arch, read_document, read_json
from ..values import is_integer

FORMAT = "oprt-sweep/1"

# Passed as `oprt render` flags (readable commands); every other parameter goes into arch.json.
FLAGS = ("frames", "resolution", "ius", "level", "quantum", "balance", "locality", "subdivide", "split", "accel", "top",
         "kernel", "precision", "tech")
SPEC_KEYS = ("format", "comment", "scenes", "frames", "resolution", "arch", "grid", "zip", "points")


def point_hash(params):
    return hashlib.sha1(json.dumps(params, sort_keys=True).encode()).hexdigest()[:10]


def load_spec(file):
    """Reads and checks a SPEC; returns (spec, points). Each point is a dict with 'params' (scene as
    written in the SPEC + every parameter), 'scene_file' (path), 'where' (JSON path it came from),
    'dir' (directory name). Raises SpecError before anything has run."""
    spec = read_document(file, FORMAT, SPEC_KEYS)
    base_dir = os.path.dirname(os.path.abspath(file))

    scenes = spec.get("scenes")
    if not isinstance(scenes, list) or not scenes or not all(isinstance(s, str) for s in scenes):
        raise SpecError(file, "/scenes", "expected a non-empty list of scene files")
    for i, scene in enumerate(scenes):
        path = os.path.join(base_dir, scene)
        if not os.path.isfile(path):
            raise SpecError(file, f"/scenes/{i}", f"no scene file {path}")

    base = {}
    if "arch" in spec:
        arch = spec["arch"]
        if isinstance(arch, str):
            arch_file = os.path.join(base_dir, arch)
            if not os.path.isfile(arch_file):
                raise SpecError(file, "/arch", f"no architecture file {arch_file}")
            arch = read_json(arch_file)
            if not isinstance(arch, dict):
                raise SpecError(arch_file, "", "expected an oprt-arch/1 object")
            base = flatten_arch(arch, arch_file)
        elif isinstance(arch, dict):
            base = flatten_arch(arch, file, "/arch")
        else:
            raise SpecError(file, "/arch", "expected an architecture file name or an oprt-arch/1 object")
    for key in ("frames", "resolution"):
        if key in spec:
            base[key] = check_value(key, spec[key], file, f"/{key}")

    # The grid: the cartesian product of the "grid" axes and the "zip" groups (parameters in one
    # group vary together), plus the explicit "points"; each for every scene. A combination is
    # (where it comes from, {parameter: value}, {parameter: JSON path of its value}).
    combos = []
    if "grid" in spec or "zip" in spec:
        grid = check_axes(spec.get("grid", {}), file, "/grid")
        groups = spec.get("zip", [])
        if not isinstance(groups, list):
            raise SpecError(file, "/zip", "expected a list of {parameter: [values]} groups")
        factors = [[{name: v} for v in values] for name, values in grid.items()]
        origins = {name: f"/grid/{name}" for name in grid}  # the list; value i is at .../i
        for g, group in enumerate(groups):
            axes = check_axes(group, file, f"/zip/{g}")
            lengths = {len(v) for v in axes.values()}
            if len(lengths) > 1:
                raise SpecError(file, f"/zip/{g}", f"lists of unequal length {sorted(lengths)}: zipped values vary together")
            for name in axes:
                if name in origins:
                    raise SpecError(file, f"/zip/{g}/{name}", f"parameter already varied at {origins[name]}")
                origins[name] = f"/zip/{g}/{name}"
            factors.append([dict(zip(axes, values)) for values in zip(*axes.values())])
        if not factors:
            raise SpecError(file, "/grid", "empty grid: name at least one parameter with a list of values")
        for chosen in itertools.product(*factors):
            combos.append(("/grid", {k: v for d in chosen for k, v in d.items()}, origins))
    explicit = spec.get("points", [])
    if not isinstance(explicit, list):
        raise SpecError(file, "/points", "expected a list of {parameter: value} objects")
    for i, p in enumerate(explicit):
        check_params(p, file, f"/points/{i}", "parameter: value")
        combos.append((f"/points/{i}", {k: check_value(k, v, file, f"/points/{i}/{k}") for k, v in p.items()},
                       {k: f"/points/{i}/{k}" for k in p}))
    if not combos:
        raise SpecError(file, "", 'nothing to sweep: give "grid", "zip" or "points"')

    points, seen = [], {}
    for scene in scenes:
        for where, combo, origins in combos:
            params = {"scene": scene, **base, **combo}
            origin = lambda key: origins.get(key, f"/{key}" if key in spec else "/arch")
            for group in ("bus",):
                named = [k for k in params if k.startswith(group + ".")]
                if named and f"{group}.model" not in params:
                    raise SpecError(file, origin(named[0]), f"{named[0]} needs {group}.model (the architecture file requires it)")
            h = point_hash(params)
            if h in seen:
                raise SpecError(file, where, f"the same point twice (also from {seen[h]}): {json.dumps(params)}")
            seen[h] = where
            stem = os.path.splitext(os.path.basename(scene))[0]
            point = {"params": params, "scene_file": os.path.join(base_dir, scene), "where": where, "dir": f"{stem}-{h}",
                     "origins": {k: origin(k) for k in params if k != "scene"}}
            for k, o in point["origins"].items():  # a listed value: its own place in the list
                if o.startswith(("/grid/", "/zip/")):
                    values = spec["grid"][k] if o.startswith("/grid/") else spec["zip"][int(o.split("/")[2])][k]
                    normal = [str(v) if k == "frames" and is_integer(v) else v for v in values]
                    point["origins"][k] = f"{o}/{normal.index(params[k])}"
            if "tech" in params:  # a technology table, relative to the SPEC
                point["tech_file"] = os.path.join(base_dir, params["tech"])
                if not os.path.isfile(point["tech_file"]):
                    raise SpecError(file, origin("tech"), f"no technology table {point['tech_file']}")
            points.append(point)
    return spec, points


def varied(points):
    """Parameter names whose value differs between points, in a stable order."""
    names = []
    for p in points:
        names += [k for k in p["params"] if k not in names]
    return [n for n in names if len({json.dumps(p["params"].get(n)) for p in points}) > 1]


def label(point, names):
    return " ".join(f"{n}={point['params'].get(n, '-')}" if n != "scene" else
                    os.path.splitext(os.path.basename(point["params"]["scene"]))[0] for n in names)


def expansion_hash(points):
    return hashlib.sha1(" ".join(p["dir"] for p in points).encode()).hexdigest()[:12]

