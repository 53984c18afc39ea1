"""Reading and checking a space file (oprt-space/1): everything that needs no oprt."""
import copy
import hashlib
import itertools
import json
import os
import re

from ..spec import read_document, SpecError, check_value, read_json
from ..values import is_integer, is_number, show
from .common import FORMAT, OBJECTIVES, RESERVED, PATH_PARAMS, SPACE_KEYS, SpaceError


# ---------------------------------------------------------------------------------- the space


class Param:
    """One parameter: kind 'int' / 'float' (lo, hi, log), 'choice' (values) or 'fixed' (value)."""

    def __init__(self, name, kind, where, lo=None, hi=None, log=False, values=None, value=None):
        self.name, self.kind, self.where = name, kind, where
        self.lo, self.hi, self.log, self.values, self.value = lo, hi, log, values, value

    @property
    def varied(self):
        return self.kind != "fixed"

    def first(self):
        return {"int": self.lo, "float": self.lo, "choice": (self.values or [None])[0]}.get(self.kind, self.value)

    def probe_values(self):
        """The values the probe renders: every choice, both ends of a range, the fixed value."""
        if self.kind == "choice":
            return list(self.values)
        if self.kind in ("int", "float"):
            return [self.lo] if self.lo == self.hi else [self.lo, self.hi]
        return [self.value]

    def size(self):
        """Number of values (None: a continuous range)."""
        return {"int": (self.hi - self.lo + 1) if self.kind == "int" else None, "float": None,
                "choice": len(self.values or []), "fixed": 1}[self.kind]

    def describe(self):
        if self.kind == "choice":
            return "{" + ", ".join(show(v) for v in self.values) + "}"
        if self.kind in ("int", "float"):
            return f"{self.kind} [{self.lo}, {self.hi}]" + (" (log)" if self.log else "")
        return f"= {show(self.value)}"

    def distribution(self, optuna):
        """Optuna's distribution of a searched parameter (as suggest asks for it)."""
        d = optuna.distributions
        if self.kind == "int":
            return d.IntDistribution(self.lo, self.hi, log=self.log)
        if self.kind == "float":
            return d.FloatDistribution(self.lo, self.hi, log=self.log)
        return d.CategoricalDistribution(self.values)

    def suggest(self, trial):
        if self.kind == "int":
            return trial.suggest_int(self.name, self.lo, self.hi, log=self.log)
        if self.kind == "float":
            return trial.suggest_float(self.name, self.lo, self.hi, log=self.log)
        if self.kind == "choice":
            return trial.suggest_categorical(self.name, self.values)
        return self.value


def parse_param(file, name, spec):
    where = f"/parameters/{name}"
    if not name or not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.-]*", name) \
            or ".." in name or name.endswith("."):
        raise SpaceError(file, where, "a parameter name is an architecture key (dotted: iu.model) or an "
                                      "oprt render option (ius)")
    if name in RESERVED:
        raise SpaceError(file, where, f"not a parameter: {RESERVED[name]}")
    if isinstance(spec, dict):
        kinds = [k for k in ("int", "float", "choice") if k in spec]
        if len(kinds) != 1:
            raise SpaceError(file, where, 'expected {"int": [lo, hi]}, {"float": [lo, hi]}, {"choice": [...]} '
                                          f"or a plain value, found {json.dumps(spec)}")
        kind = kinds[0]
        allowed = {kind, "log"} if kind != "choice" else {kind}
        for key in spec:
            if key not in allowed:
                raise SpaceError(file, f"{where}/{key}", f"unknown key (expected: {', '.join(sorted(allowed))})")
        if kind == "choice":
            values = spec["choice"]
            if not isinstance(values, list):
                raise SpaceError(file, f"{where}/choice", f"expected a list of values, found {json.dumps(values)}")
            if not values:
                raise SpaceError(file, f"{where}/choice", "empty choice: nothing to choose from")
            for i, v in enumerate(values):
                if not (isinstance(v, (str, bool)) or is_number(v)):
                    raise SpaceError(file, f"{where}/choice/{i}",
                                     f"a choice is a string, a number or true/false, found {json.dumps(v)}")
                if any(v == w and type(v) is type(w) for w in values[:i]):
                    raise SpaceError(file, f"{where}/choice/{i}", f"value {json.dumps(v)} is listed twice")
            return Param(name, "choice", where, values=list(values))
        bounds = spec[kind]
        check = is_integer if kind == "int" else is_number
        if not (isinstance(bounds, list) and len(bounds) == 2 and all(check(b) for b in bounds)):
            raise SpaceError(file, f"{where}/{kind}",
                             f"expected [lo, hi], two {'integers' if kind == 'int' else 'numbers'}, found {json.dumps(bounds)}")
        lo, hi = bounds
        if lo > hi:
            raise SpaceError(file, f"{where}/{kind}", f"empty range [{lo}, {hi}]: lo is above hi")
        log = spec.get("log", False)
        if not isinstance(log, bool):
            raise SpaceError(file, f"{where}/log", f"expected true or false, found {json.dumps(log)}")
        if log and lo <= 0:
            raise SpaceError(file, f"{where}/{kind}", f"a log range needs lo > 0, found [{lo}, {hi}]")
        return Param(name, kind, where, lo=lo, hi=hi, log=log)
    if isinstance(spec, (str, bool)) or is_number(spec) or \
            (isinstance(spec, list) and all(isinstance(v, (str, bool)) or is_number(v) for v in spec)):
        return Param(name, "fixed", where, value=spec)
    raise SpaceError(file, where, 'expected {"int": [lo, hi]}, {"float": [lo, hi]}, {"choice": [...]} '
                                  f"or a plain value, found {json.dumps(spec)}")


class Space:
    pass


def load_space(file):
    """Reads and checks a space file (everything that needs no oprt); raises SpaceError."""
    doc = read_document(file, FORMAT, SPACE_KEYS, SpaceError)  # SpecError on unreadable or malformed JSON
    s = Space()
    s.file = os.path.abspath(file)
    s.dir = os.path.dirname(s.file)
    s.doc = doc
    s.comment = doc.get("comment", "")

    _scenes(s, doc, file)
    _base_arch(s, doc, file)
    _parameters(s, doc, file)
    _objectives(s, doc, file)
    _references(s, doc, file)
    _start(s, doc, file)
    _hashes(s, doc, file)
    return s


def _scenes(s, doc, file):
    """The scenes (each a file), the frames and the resolution."""
    scenes = doc.get("scenes")
    if not isinstance(scenes, list) or not scenes or not all(isinstance(x, str) for x in scenes):
        raise SpaceError(file, "/scenes", "expected a non-empty list of scene files")
    s.scenes, s.scene_files = scenes, []
    frame_counts = []
    for i, scene in enumerate(scenes):
        path = os.path.join(s.dir, scene)
        if not os.path.isfile(path):
            raise SpaceError(file, f"/scenes/{i}", f"no scene file {path}")
        if scenes.index(scene) != i:
            raise SpaceError(file, f"/scenes/{i}", f"{scene} is listed twice")
        s.scene_files.append(os.path.normpath(path))
        count = None
        if path.endswith(".json"):
            try:
                scene_doc = read_json(path)
                count = scene_doc.get("frames", 1) if isinstance(scene_doc, dict) else None
            except SpecError:
                count = None  # oprt says what is wrong with it (the probe)
        frame_counts.append(count if is_integer(count) else None)
    s.frames = _text_value(doc, "frames", file)
    if s.frames:
        last = int(s.frames.split(":")[-1])
        for scene, count in zip(scenes, frame_counts):
            if count is not None and last >= count:
                raise SpaceError(file, "/frames", f"frames {s.frames}: {scene} has frames 0:{count - 1} only")
    s.first_frame = s.frames.split(":")[0] if s.frames else "0"
    s.resolution = _text_value(doc, "resolution", file)


def _text_value(doc, key, file):
    """The space's "frames" or "resolution" as oprt takes it (text), or None where not given."""
    if key not in doc:
        return None
    try:
        return check_value(key, doc[key], file, f"/{key}")
    except SpecError as e:
        raise SpaceError(file, f"/{key}", str(e).split(": ", 2)[-1])


def _base_arch(s, doc, file):
    """The base architecture: a file (relative to the space) or an inline oprt-arch/1 object."""
    s.base_arch = {"format": "oprt-arch/1"}
    if "arch" in doc:
        arch = doc["arch"]
        if isinstance(arch, str):
            path = os.path.join(s.dir, arch)
            if not os.path.isfile(path):
                raise SpaceError(file, "/arch", f"no architecture file {path}")
            try:
                arch = read_json(path)
            except SpecError as e:
                raise SpaceError(file, "/arch", str(e))
        if not isinstance(arch, dict):
            raise SpaceError(file, "/arch", "expected an architecture file name or an oprt-arch/1 object")
        s.base_arch = copy.deepcopy(arch)
        s.base_arch.setdefault("format", "oprt-arch/1")


def _parameters(s, doc, file):
    """The parameters, each a name oprt takes and a domain."""
    params = doc.get("parameters")
    if not isinstance(params, dict) or not params:
        raise SpaceError(file, "/parameters", "expected an object of parameters {name: domain}")
    s.params = [parse_param(file, name, spec) for name, spec in params.items()]
    s.by_name = {p.name: p for p in s.params}
    if not any(p.varied for p in s.params):
        raise SpaceError(file, "/parameters", "nothing to search: every parameter is fixed")
    for p in s.params:
        if p.name in PATH_PARAMS:
            for i, v in enumerate(p.probe_values() if p.kind != "fixed" else [p.value]):
                path = os.path.join(s.dir, v) if isinstance(v, str) else None
                if not path or not os.path.isfile(path):
                    raise SpaceError(file, p.where + (f"/choice/{i}" if p.kind == "choice" else ""),
                                     f"{p.name}: no file {path or json.dumps(v)} (paths are relative to the space file)")
        # A dotted name must fit in the base architecture (no value where it needs an object).
        node, parts = s.base_arch, p.name.split(".")
        for depth, part in enumerate(parts[:-1]):
            node = node.get(part, {}) if isinstance(node, dict) else None
            if not isinstance(node, dict):
                raise SpaceError(file, p.where, f"the base architecture's {'.'.join(parts[:depth + 1])} is a value, "
                                                f"not an object holding {p.name}")
    for a, b in itertools.permutations(s.params, 2):
        if b.name.startswith(a.name + ".") and "." in a.name:
            raise SpaceError(file, b.where, f"{b.name} is inside {a.name}, which is a parameter itself")


def _objectives(s, doc, file):
    """The objectives, the bounds (constraints) and NSGA-II's generation size."""
    objectives = doc.get("objectives", ["frame_time_s", "energy_j", "area_mm2"])
    if not isinstance(objectives, list) or not 2 <= len(objectives) <= 3:
        raise SpaceError(file, "/objectives", f"expected two or three of {', '.join(OBJECTIVES)}")
    for i, o in enumerate(objectives):
        if o not in OBJECTIVES:
            raise SpaceError(file, f"/objectives/{i}", f"unknown objective {json.dumps(o)} (expected one of: "
                                                       f"{', '.join(OBJECTIVES)})")
        if objectives.index(o) != i:
            raise SpaceError(file, f"/objectives/{i}", f"{o} is listed twice")
    s.objectives = objectives

    constraints = doc.get("constraints", {})
    if not isinstance(constraints, dict):
        raise SpaceError(file, "/constraints", 'expected an object {key: {"max": number}}')
    s.constraints = []  # (key, bound, "max"|"min", where)
    for key, c in constraints.items():
        where = f"/constraints/{key}"
        if not isinstance(c, dict) or not c:
            raise SpaceError(file, where, f'expected {{"max": number}} (or "min"), found {json.dumps(c)}')
        for kind, bound in c.items():
            if kind not in ("max", "min"):
                raise SpaceError(file, f"{where}/{kind}", 'unknown bound (expected "max" or "min")')
            if not is_number(bound):
                raise SpaceError(file, f"{where}/{kind}", f"expected a number, found {json.dumps(bound)}")
            s.constraints.append((key, float(bound), kind, f"{where}/{kind}"))
        if "max" in c and "min" in c and c["min"] > c["max"]:
            raise SpaceError(file, where, f"min {c['min']} is above max {c['max']}: nothing can satisfy it")
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+)*", key):
            raise SpaceError(file, where, "expected an objective or a per-frame stats.json key (dotted: energy_j.total)")

    s.population = doc.get("population")
    if s.population is not None and not (is_integer(s.population) and s.population >= 2):
        raise SpaceError(file, "/population", f"expected an integer >= 2 (NSGA-II's generation), found {json.dumps(s.population)}")


def _references(s, doc, file):
    """Reference configurations: marked on the plots, compared in the summary; the first one also
    fixes the hypervolume's reference point where no bound does."""
    tech = s.by_name.get("tech")
    default_ref = {"ius": 32, "iu.model": "serial"}
    if tech:
        default_ref["tech"] = tech.first()
    refs = doc.get("references", {"paper: 32 serial IUs": default_ref})
    if not isinstance(refs, dict):
        raise SpaceError(file, "/references", "expected an object {name: {parameter: value}}")
    s.references = []
    for name, ref in refs.items():
        where = f"/references/{name}"
        if not isinstance(ref, dict):
            raise SpaceError(file, where, "expected an object {parameter: value}")
        for k, v in ref.items():
            if k in RESERVED:
                raise SpaceError(file, f"{where}/{k}", f"not a parameter: {RESERVED[k]}")
            if not (isinstance(v, (str, bool)) or is_number(v) or isinstance(v, list)):
                raise SpaceError(file, f"{where}/{k}", f"expected a plain value, found {json.dumps(v)}")
            if k in PATH_PARAMS and not os.path.isfile(os.path.join(s.dir, str(v))):
                raise SpaceError(file, f"{where}/{k}", f"{k}: no file {os.path.join(s.dir, str(v))}")
        s.references.append((name, dict(ref)))


def _start(s, doc, file):
    """Configurations the search evaluates first (known designs: Optuna's enqueue_trial), each
    giving every searched parameter a value of its domain."""
    start = doc.get("start", [])
    if not isinstance(start, list):
        raise SpaceError(file, "/start", "expected a list of configurations {parameter: value}")
    s.start = []
    for i, point in enumerate(start):
        where = f"/start/{i}"
        if not isinstance(point, dict):
            raise SpaceError(file, where, "expected an object {parameter: value}")
        for k in point:
            if k not in s.by_name:
                raise SpaceError(file, f"{where}/{k}", "not a parameter of this space")
            if not s.by_name[k].varied:
                raise SpaceError(file, f"{where}/{k}", f"{k} is fixed at {show(s.by_name[k].value)}: leave it out")
        for p in s.params:
            if not p.varied:
                continue
            if p.name not in point:
                raise SpaceError(file, where, f"no value for {p.name}: a start point gives every searched parameter")
            v = point[p.name]
            ok = (p.kind == "choice" and any(v == c and type(v) is type(c) for c in p.values)) or \
                 (p.kind == "int" and is_integer(v) and p.lo <= v <= p.hi) or \
                 (p.kind == "float" and is_number(v) and p.lo <= v <= p.hi)
            if not ok:
                raise SpaceError(file, f"{where}/{p.name}", f"{show(v)} is not in {p.name}'s domain {p.describe()}")
        s.start.append(dict(point))


def _hashes(s, doc, file):
    """The given reference point, and the hashes that tell searches and evaluations apart."""
    rp = doc.get("reference_point", {})
    if not isinstance(rp, dict):
        raise SpaceError(file, "/reference_point", "expected an object {objective: value}")
    for k, v in rp.items():
        if k not in s.objectives:
            raise SpaceError(file, f"/reference_point/{k}", f"not an objective of this space ({', '.join(s.objectives)})")
        if not is_number(v) or v <= 0:
            raise SpaceError(file, f"/reference_point/{k}", f"expected a positive number, found {json.dumps(v)}")
    s.reference_point_given = dict(rp)
    # What decides an evaluation's outcome (for --reuse): the scenes, frames, resolution, base
    # architecture and bounds, paths resolved.
    s.eval_hash = hashlib.sha1(json.dumps([s.scene_files, s.frames, s.resolution, s.base_arch,
                                           sorted(map(list, [c[:3] for c in s.constraints]))],
                                          sort_keys=True).encode()).hexdigest()[:12]
    s.hash = hashlib.sha1(json.dumps({k: doc.get(k) for k in SPACE_KEYS if k not in ("comment",)},
                                     sort_keys=True).encode()).hexdigest()[:12]
    # A grid evaluates every point whatever the search's start and generation size.
    s.grid_hash = hashlib.sha1(json.dumps({k: doc.get(k) for k in SPACE_KEYS if k not in ("comment", "start", "population")},
                                          sort_keys=True).encode()).hexdigest()[:12]
