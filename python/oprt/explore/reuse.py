"""Starting from what is known (--reuse DIR): the evaluated points of an earlier explore output or
of a sweep's aggregate.csv, on the same scenes, frames and resolution, added to the study as
finished trials (Optuna's add_trial), so that the sampler starts from them and the front holds
them; the configurations they price are not rendered again."""
import csv
import os

from ..values import is_number
from .common import PATH_PARAMS, UsageError, config_key
from .evaluate import judge
from .fidelity import TARGET
from .storage import load_reused


def in_domain(p, v):
    if p.kind == "choice":
        return any(v == c and isinstance(v, bool) == isinstance(c, bool) for c in p.values)
    if p.kind in ("int", "float"):
        return is_number(v) and p.lo <= v <= p.hi and (p.kind == "float" or float(v).is_integer())
    return v == p.value


def as_value(p, text):
    """A CSV cell as the parameter's type (a choice's own value when one matches)."""
    candidates = p.values if p.kind == "choice" else [p.value] if p.kind == "fixed" else []
    for c in candidates:
        if str(c) == text or (isinstance(c, bool) and text.lower() == str(c).lower()):
            return c
        if is_number(c) and not isinstance(c, bool):
            try:
                if float(text) == c:
                    return c
            except ValueError:
                pass
    try:
        return int(text) if p.kind == "int" else float(text)
    except ValueError:
        return text


def my_file(p, other, same):
    """A file parameter's value as this space gives it, for `other` (another output's file) when
    `same` maps both to the same name; else `other` itself (then out of the domain)."""
    for mine in (p.values if p.kind == "choice" else [p.value]):
        if isinstance(mine, str) and same(mine) == same(other):
            return mine
    return other


def sweep_points(space, path):
    """(config, record) per point of a sweep's aggregate.csv with a row for every frame of every
    scene of the space, at its resolution; tech compared as files."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    scenes = [os.path.basename(s) for s in space.scene_files]
    points = {}
    for r in rows:
        if r.get("resolution") not in (space.resolution, None, "") or os.path.basename(r.get("scene", "")) not in scenes:
            continue
        points.setdefault(r["point"], []).append(r)
    out = []
    for rs in points.values():
        if {os.path.basename(r["scene"]) for r in rs} != set(scenes):
            continue
        config, ok = {}, True
        for p in space.params:
            if p.name not in rs[0]:
                ok = False
                break
            text = rs[0][p.name]
            config[p.name] = my_file(p, text, os.path.basename) if p.name in PATH_PARAMS else as_value(p, text)
        if not ok:
            continue
        try:
            ft = [float(r["frame_time_s"]) for r in rs]
            en = [float(r["energy_j"]) for r in rs]
            figures = {"frame_time_s": sum(ft) / len(ft), "energy_j": sum(en) / len(en),
                       "area_mm2": max(float(r["area_mm2"]) for r in rs)}
        except (KeyError, ValueError):
            continue
        out.append((config, {"figures": figures, "wall_s": 0.0}))
    return out


def known_points(run, folder):
    """(config, record) of every rendered evaluation `folder` holds (explore or sweep output)."""
    if os.path.isfile(os.path.join(folder, "explore.json")):
        table = load_reused(run.optuna, folder, run.space)
        out = []
        for key, rec in table.items():
            if not key.endswith("@") or not rec.get("figures"):
                continue  # screened at another resolution, or refused
            config = dict(rec["config"])
            for p in run.space.params:
                if p.name in PATH_PARAMS and isinstance(config.get(p.name), str):
                    config[p.name] = my_file(p, config[p.name], lambda f: os.path.normpath(os.path.join(run.space.dir, f))
                                             if not os.path.isabs(f) else f)
            out.append((config, rec))
        return out
    agg = folder if folder.endswith(".csv") else os.path.join(folder, "aggregate.csv")
    if os.path.isfile(agg):
        return sweep_points(run.space, agg)
    raise UsageError(f"--reuse {folder}: neither an explore output (explore.json) nor a sweep output (aggregate.csv)")


def seed_study(run, folder):
    """Adds the known points that lie in the space as finished trials; returns how many."""
    optuna = run.optuna
    taken = {config_key(run.evaluation(t)["config"]) for t in run.trials() if run.evaluation(t)}
    n = 0
    for config, rec in known_points(run, folder):
        if set(config) != {p.name for p in run.space.params} or \
                not all(in_domain(p, config[p.name]) for p in run.space.params):
            continue
        if config_key(config) in taken:
            continue
        taken.add(config_key(config))
        figures = rec["figures"]
        if "violations" in rec:  # an explore output's own judgement
            violations, values, outcome, reason = rec["violations"], rec["constraint_values"], rec["outcome"], rec["reason"]
        else:
            violations, broken, values = judge(run.space, figures, [])
            outcome, reason = "infeasible" if broken else "complete", "; ".join(broken)
        evaluation = {"outcome": outcome, "reason": reason, "config": config,
                      "figures": figures, "constraint_values": values, "violations": violations,
                      "wall_s": rec.get("wall_s", 0.0), "violations_all": violations + [0.0],
                      "resolution": run.space.resolution}
        varied = [p for p in run.varied]
        dists = {p.name: p.distribution(optuna) for p in varied}
        screened = bool(run.screen)
        trial = optuna.trial.create_trial(
            state=optuna.trial.TrialState.PRUNED if screened else optuna.trial.TrialState.COMPLETE,
            values=None if screened else [figures[o] for o in run.space.objectives],
            params={p.name: config[p.name] for p in varied}, distributions=dists,
            user_attrs={"evaluation": evaluation, "config": config, "fidelity": TARGET, "reused_from": folder},
            # NSGA-II takes them as its first generation (it reads only trials with a generation).
            system_attrs={"constraints": evaluation["violations_all"], "nsga2:generation": 0})
        run.study.add_trial(trial)
        n += 1
    return n
