"""The reference configurations and the confirmation of the front at --level at."""
import json
import os
import re
import shlex
import time

from .. import paths
from ..files import atomic_json
from .common import OBJECTIVES, SpaceError
from .evaluate import Evaluation


# ------------------------------------------------------------------------ references, confirm
def slug(text):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_") or "reference"


def run_batch(run, jobs_list):
    """Runs Evaluations built by the callables in jobs_list, up to --jobs at once; returns their
    results in order. Stops (and returns None) on a signal."""
    results = [None] * len(jobs_list)
    pending = list(enumerate(jobs_list))
    active = []
    try:
        while pending or active:
            if run.stop_signal:
                return None
            while pending and len(active) < run.jobs:
                i, make = pending.pop(0)
                active.append((i, make()))
            for item in list(active):
                i, ev = item
                if ev.poll():
                    active.remove(item)
                    results[i] = ev
            time.sleep(0.02)
    finally:
        for _, ev in active:
            ev.stop()
    return results


def evaluate_references(run):
    """The reference configurations at the analytic level (cached in DIR/references)."""
    out = []
    todo = []
    for name, ref in run.space.references:
        folder = os.path.join(run.out, "references", slug(name))
        cached = os.path.join(folder, "result.json")
        if os.path.isfile(cached):
            with open(cached) as f:
                out.append((name, ref, json.load(f)))
            continue
        out.append((name, ref, None))
        todo.append((len(out) - 1, name, ref, folder))
    evs = run_batch(run, [lambda r=ref, f=folder: Evaluation(run, 0, r, folder=f) for _, _, ref, folder in todo])
    if evs is None:
        return None
    for (i, name, ref, folder), ev in zip(todo, evs):
        result = dict(ev.result, wall_s=round(ev.wall, 3))
        atomic_json(os.path.join(folder, "result.json"), result)
        out[i] = (name, ref, result)
    return out


def reference_point(space, references):
    """Per objective: the space's reference_point, else its upper bound, else the first
    reference configuration's figure."""
    point = {}
    for o in space.objectives:
        if o in space.reference_point_given:
            point[o] = float(space.reference_point_given[o])
            continue
        bound = [b for k, b, kind, _ in space.constraints if k == o and kind == "max" and b > 0]
        if bound:
            point[o] = min(bound)
            continue
        figures = references[0][2].get("figures") if references and references[0][2] else None
        if not figures or not figures.get(o, 0) > 0:
            raise SpaceError(space.file, "/reference_point",
                             f"no reference value for {o}: the first reference configuration has none "
                             f"({(references[0][2] or {}).get('reason', 'no reference') if references else 'no reference'}); "
                             "give \"reference_point\"")
        point[o] = figures[o]
    return point


def confirm(run, front):
    """The Pareto points again at --level at, each from its own architecture file (which must
    therefore be complete); returns rows of confirm.csv, or None on a signal."""
    os.makedirs(os.path.join(run.out, "pareto"), exist_ok=True)
    rows, todo = {}, []
    for t in front:
        e = run.evaluation(t)
        arch = os.path.join(run.out, "pareto", f"trial_{t.number:05d}.json")
        doc = run.oprt.arch_doc(e["config"], fold=True)
        doc["comment"] = (f"Pareto point of {os.path.relpath(run.space.file, paths.REPO) if run.space.file.startswith(paths.REPO) else run.space.file}"
                          f" (scripts/explore, trial {t.number})")
        atomic_json(arch, doc)
        folder = os.path.join(run.out, "confirm", f"trial_{t.number:05d}")
        cached = os.path.join(folder, "result.json")
        if os.path.isfile(cached):
            with open(cached) as f:
                rows[t.number] = json.load(f)
            continue
        todo.append((t, arch, folder))
    evs = run_batch(run, [lambda t=t, a=arch, f=folder: Evaluation(run, t.number, run.evaluation(t)["config"],
                                                                  level="at", folder=f, arch_doc=a, fold=True)
                          for t, arch, folder in todo])
    if evs is None:
        return None
    for (t, arch, folder), ev in zip(todo, evs):
        fa = run.evaluation(t)["figures"]
        r = ev.result
        row = {"trial": t.number, "command": " ".join(shlex.quote(shown_path(c)) for c in ev.cmd),
               "at_wall_s": round(ev.wall, 3)}
        if "figures" not in r:
            row.update({"state": "failed", "reason": r.get("reason", "")})
        else:
            fb = r["figures"]
            row["state"] = "confirmed"
            for o in OBJECTIVES:
                row[f"{o}_analytic"] = fa[o]
                row[f"{o}_at"] = fb[o]
                row[f"{o}_error_pct"] = abs(fa[o] - fb[o]) / abs(fb[o]) * 100 if fb[o] else (0.0 if fa[o] == 0 else 100.0)
        atomic_json(os.path.join(folder, "result.json"), row)
        rows[t.number] = row
    return [rows[t.number] for t in front]


def shown_path(p):
    """A path as printed in commands: relative to the repository when inside it."""
    if os.path.isabs(p) and os.path.exists(p):
        rel = os.path.relpath(p, paths.REPO)
        return rel if not rel.startswith("..") else p
    return p
