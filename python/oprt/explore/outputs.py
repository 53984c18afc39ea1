"""The outputs of a search: evaluations.csv, pareto.csv, hypervolume.csv, result.json, plots, summary.md."""
import os
import re

from .. import plots
from ..files import atomic_json, atomic_write, csv_text
from ..pareto import pareto_front
from ..plots import atomic_savefig
from ..values import show
from .common import RUN_FORMAT, OBJECTIVES, UNITS, AXIS_LABELS
from .study import best_for, pareto_trials
from .fidelity import SCREEN, TARGET, UNBOUNDED, fidelity_error


# ------------------------------------------------------------------------------------ outputs
def hypervolume_curve(run, done):
    """(evaluations, trial, hypervolume of the target-fidelity front) after each evaluation, in
    trial order (screened ones included: they cost time too)."""
    curve = []
    saved, run.front = run.front, []
    for i, t in enumerate(sorted(done, key=lambda t: t.number), 1):
        before = list(run.front)
        run.add_to_front(t)
        if run.front != before or not curve:
            hv = run.hypervolume([run.evaluation(x)["figures"] for x in run.front]) if run.front else 0.0
        else:
            hv = curve[-1][2]
        curve.append((i, t.number, hv))
    run.front = saved
    return curve


def plot_outputs(run, done, front, references, curve):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ev = run.evaluation
    measured = [t for t in done if ev(t).get("figures")]
    feasible = [t for t in measured if ev(t)["outcome"] == "complete"]
    broken = [t for t in measured if ev(t)["outcome"] != "complete"]
    front_set = {t.number for t in front}
    colour_by = "iu.model" if "iu.model" in run.space.by_name and run.space.by_name["iu.model"].varied else None
    bounds = {}
    for key, bound, kind, _ in run.space.constraints:
        if key in OBJECTIVES:
            bounds.setdefault(key, []).append((bound, kind))

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), constrained_layout=True)
    panels = (("area_mm2", "frame_time_s"), ("frame_time_s", "energy_j"))
    for ax, (x, y) in zip(axes, panels):
        sx, sy = UNITS[x][0], UNITS[y][0]
        pt = lambda t: (ev(t)["figures"][x] * sx, ev(t)["figures"][y] * sy)
        if broken:
            ax.scatter([pt(t)[0] for t in broken], [pt(t)[1] for t in broken], s=14, marker="x", color="#bbbbbb",
                       label="breaks a constraint")
        groups = sorted({str(ev(t)["config"].get(colour_by)) for t in feasible}) if colour_by else [None]
        for g in groups:
            mine = [t for t in feasible if colour_by is None or str(ev(t)["config"].get(colour_by)) == g]
            colour = plots.MODEL_COLOURS.get(g, "#4878d0") if g else "#4878d0"
            name = g or "feasible"
            rest = [t for t in mine if t.number not in front_set]
            on = [t for t in mine if t.number in front_set]
            ax.scatter([pt(t)[0] for t in rest], [pt(t)[1] for t in rest], s=26, facecolors="none", edgecolors=colour,
                       label=name)
            ax.scatter([pt(t)[0] for t in on], [pt(t)[1] for t in on], s=42, color=colour, label=f"{name}, Pareto-optimal")
        # The front of this pair of figures alone (plot_sweep's rule), as a step line.
        pts = [{"x": pt(t)[0], "y": pt(t)[1]} for t in feasible]
        f2 = pareto_front(pts, "x", "y")
        ax.step([p["x"] for p in f2], [p["y"] for p in f2], where="post", color="black", linewidth=0.8, alpha=0.6)
        for key, axis_line in ((x, ax.axvline), (y, ax.axhline)):
            for bound, kind in bounds.get(key, []):
                axis_line(bound * UNITS[key][0], color="#d65f5f", linestyle="--", linewidth=1,
                          label=f"{key} {kind} {bound * UNITS[key][0]:g} {UNITS[key][1]}")
        for i, (name, _, result) in enumerate(references or []):
            f = (result or {}).get("figures")
            if f:
                ax.scatter([f[x] * sx], [f[y] * sy], marker="*", s=220, color="black", zorder=5,
                           label="reference" if i == 0 else None)
                ax.annotate(name, (f[x] * sx, f[y] * sy), textcoords="offset points", xytext=(6, 6), fontsize=8)
        values_x = [pt(t)[0] for t in measured] or [1]
        values_y = [pt(t)[1] for t in measured] or [1]
        for vals, set_scale, axis in ((values_x, ax.set_xscale, ax.xaxis), (values_y, ax.set_yscale, ax.yaxis)):
            if min(vals) > 0 and max(vals) > 4 * min(vals):
                set_scale("log")
                axis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.set_xlabel(AXIS_LABELS[x])
        ax.set_ylabel(AXIS_LABELS[y])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{os.path.basename(run.space.file)}: {len(done)} evaluations, {len(front)} Pareto-optimal "
                 f"(filled; objectives {', '.join(run.space.objectives)})", fontsize=10)
    atomic_savefig(fig, os.path.join(run.out, "front.png"))
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(7, 4.2), constrained_layout=True)
    ax.plot([c[0] for c in curve], [c[2] for c in curve], color="#4878d0", drawstyle="steps-post")
    ax.set_xlabel("evaluations")
    ax.set_ylabel("hypervolume (normalised)")
    ref = ", ".join(f"{o} {run.reference_point[o] * UNITS[o][0]:g} {UNITS[o][1]}" for o in run.space.objectives)
    ax.set_title(f"hypervolume of the feasible front; reference point {ref}", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    atomic_savefig(fig, os.path.join(run.out, "hypervolume.png"))
    plt.close(fig)


def fmt(o, v):
    return f"{v * UNITS[o][0]:.4g} {UNITS[o][1]}"


def write_outputs(run, references, confirmed, note, plots=True):
    done = run.done()
    ev = run.evaluation
    feasible = [t for t in run.final(done) if ev(t)["outcome"] == "complete"]
    front = pareto_trials(run, feasible)
    run.write_evaluations()
    atomic_write(os.path.join(run.out, "pareto.csv"), csv_text(run.columns(), [run.row(t) for t in front]))
    curve = hypervolume_curve(run, done)
    atomic_write(os.path.join(run.out, "hypervolume.csv"),
                 csv_text(["evaluations", "trial", "hypervolume"],
                          [{"evaluations": n, "trial": k, "hypervolume": repr(h)} for n, k, h in curve]))
    if confirmed:
        fields = ["trial", "state", "reason"] + [f"{o}_{s}" for o in OBJECTIVES for s in ("analytic", "at", "error_pct")] + \
                 ["at_wall_s", "command"]
        atomic_write(os.path.join(run.out, "confirm.csv"),
                     csv_text(fields, [{k: r.get(k, "") for k in fields} for r in confirmed]))
    final_hv = curve[-1][2] if curve else 0.0
    result = {"format": RUN_FORMAT, "evaluations": len(done), "requested": run.target,
              "states": {s: sum(1 for t in done if ev(t)["outcome"] == s) for s in ("complete", "infeasible", "failed")},
              "pareto_trials": [t.number for t in front], "hypervolume": final_hv,
              "reference_point": run.reference_point, "note": note,
              "confirmation_max_error_pct": max((max(r.get(f"{o}_error_pct", 0) for o in ("frame_time_s", "energy_j"))
                                                 for r in confirmed or [] if r.get("state") == "confirmed"), default=None)}
    result.update(time_and_fidelity(run, done))
    if result["fidelity_error"]:
        atomic_write(os.path.join(run.out, "fidelity.csv"), csv_text(list(result["fidelity_error"][0]),
                                                                     [{k: repr(v) if isinstance(v, float) else v
                                                                       for k, v in r.items()}
                                                                      for r in result["fidelity_error"]]))
    atomic_json(os.path.join(run.out, "result.json"), result)
    if plots:
        plot_outputs(run, done, front, references, curve)
    atomic_write(os.path.join(run.out, "summary.md"), summary(run, done, front, references, confirmed, curve, note))
    return front


def summary(run, done, front, references, confirmed, curve, note):
    s, ev = run.space, run.evaluation
    varied = [p for p in s.params if p.varied]
    fixed = [p for p in s.params if not p.varied]
    states = {k: [t for t in run.final(done) if ev(t)["outcome"] == k] for k in ("complete", "infeasible", "failed")}
    refused = [t for t in states["infeasible"] if not ev(t).get("figures")]
    broke = [t for t in states["infeasible"] if ev(t).get("figures")]
    L = [f"# Design-space search: {os.path.basename(s.file)}", ""]
    if s.comment:
        L += [s.comment, ""]
    mode = "every point of the grid" if run.args.grid else f"Optuna's {'NSGA-II' if run.args.sampler == 'nsga2' else 'TPE'} sampler, seed {run.args.seed}"
    L += [f"Scenes {', '.join(s.scenes)}, frames {s.frames or 'all'}, resolution {s.resolution or 'as in the scene'}; "
          f"{len(varied)} parameters searched ({mode}), each configuration priced at `--level analytic`.", ""]
    L += ["| parameter | domain |", "|---|---|"] + [f"| `{p.name}` | {p.describe()} |" for p in s.params] + [""]
    if fixed:
        L += ["Fixed: " + ", ".join(f"`{p.name}` = {show(p.value)}" for p in fixed) + ".", ""]
    cons = "; ".join(f"{k} {'<=' if kind == 'max' else '>='} {b:g}" for k, b, kind, _ in s.constraints) or "none"
    L += [f"Objectives (all minimised): {', '.join(s.objectives)}. Constraints: {cons}.", ""]
    L += ["## What the search found", ""]
    asked = f" (of {run.target} requested)" if run.target < UNBOUNDED else ""
    at = f" at the target fidelity ({s.resolution})" if run.screen else ""
    L += [f"{len(done)} evaluations{asked}; {len(run.final(done))}{at}: {len(states['complete'])} feasible, "
          f"{len(broke)} breaking a constraint, {len(refused)} refused by oprt, {len(states['failed'])} failed."]
    if note:
        L += [f"The search stopped early: {note}."]
    reasons = {}
    for t in refused + states["failed"]:
        r = ev(t)["reason"]
        r = re.sub(r"^refused by oprt(?: \([^)]*\))?: ", "", r).split(": ")[0]
        reasons[r] = reasons.get(r, 0) + 1
    if reasons:
        L += ["Refusals and failures, by cause: " + "; ".join(f"{r} ({n})" for r, n in
                                                               sorted(reasons.items(), key=lambda x: -x[1])) + "."]
    L += [""]
    if front:
        L += [f"**{len(front)} configurations are Pareto-optimal** (no other feasible one is as good in every "
              "objective and better in one); each has an architecture file in `pareto/` that "
              "`oprt render --arch` takes as it is:", ""]
        cols = [p.name for p in varied]
        conf = {r["trial"]: r for r in confirmed or []}
        head = ["trial"] + cols + ["frame (ms)", "energy (mJ)", "area (mm2)", "at error"]
        L += ["| " + " | ".join(head) + " |", "|" + "---:|" * len(head)]
        for t in front:
            e = ev(t)
            c = conf.get(t.number, {})
            err = (f"{max(c['frame_time_s_error_pct'], c['energy_j_error_pct']):.3f} %" if c.get("state") == "confirmed"
                   else c.get("state", "not run"))
            L += ["| " + " | ".join([str(t.number)] + [show(e["config"][k]) for k in cols] +
                                    [f"{e['figures']['frame_time_s'] * 1e3:.2f}", f"{e['figures']['energy_j'] * 1e3:.3f}",
                                     f"{e['figures']['area_mm2']:.2f}", err]) + " |"]
        L += [""]
        for o in s.objectives:
            t = best_for(run, states["complete"], o)
            f = ev(t)["figures"]
            L += [f"- Lowest {o} within the constraints: trial {t.number} ("
                  + ", ".join(f"{k}={show(ev(t)['config'][k])}" for k in cols) + f"): "
                  + ", ".join(fmt(k, f[k]) for k in OBJECTIVES) + "."]
        fastest = min(states["complete"], key=lambda t: ev(t)["figures"]["frame_time_s"])
        for name, ref, result in references or []:
            f = (result or {}).get("figures")
            if f:
                ok = "meets" if result["outcome"] == "complete" else f"does not meet ({result['reason']})"
                L += [f"- Reference **{name}**: " + ", ".join(fmt(k, f[k]) for k in OBJECTIVES) +
                      f"; it {ok} the constraints. The fastest feasible configuration found is "
                      f"{f['frame_time_s'] / ev(fastest)['figures']['frame_time_s']:.2f}x faster."]
            else:
                L += [f"- Reference **{name}**: {(result or {}).get('reason', 'not evaluated')}."]
        L += [""]
    else:
        L += ["No evaluated configuration meets the constraints.", ""]
    if curve:
        final = curve[-1][2]
        reach = next((n for n, _, h in curve if h >= 0.95 * final), None) if final > 0 else None
        ref = ", ".join(f"{o} {fmt(o, run.reference_point[o])}" for o in s.objectives)
        L += [f"Hypervolume of the feasible front: **{final:.4f}** (each objective divided by its reference value, "
              f"reference point {ref}: 1 would be a configuration costing nothing)"
              + (f"; 95 % of it was reached after {reach} of {len(done)} evaluations." if reach else ".") + "", ""]
    if confirmed:
        ok = [r for r in confirmed if r.get("state") == "confirmed"]
        worst = max(ok, key=lambda r: max(r["frame_time_s_error_pct"], r["energy_j_error_pct"]), default=None)
        bad = [r for r in confirmed if r.get("state") != "confirmed" or
               max(r["frame_time_s_error_pct"], r["energy_j_error_pct"]) > 1.0]
        if worst:
            L += [f"Confirmation: the {len(confirmed)} Pareto configurations rendered again at `--level at` "
                  f"(confirm.csv); the largest difference from the analytic level is "
                  f"{max(worst['frame_time_s_error_pct'], worst['energy_j_error_pct']):.4f} % (trial {worst['trial']})."]
        if bad:
            L += ["", f"**CONFIRMATION FAILED for {len(bad)} configuration(s): the analytic level is more than 1 % off "
                      "(or the at run failed): trials " + ", ".join(str(r["trial"]) for r in bad) + ".**"]
        L += [""]
        L += ["Each Pareto point's command at the timing reference (from the repository):", ""]
        L += [f"    {r['command']}" for r in confirmed[:20]]
        if len(confirmed) > 20:
            L += [f"    ... ({len(confirmed) - 20} more in confirm.csv)"]
        L += [""]
    L += time_lines(run, done)
    L += ["Files: evaluations.csv (every evaluation), pareto.csv (the front), pareto/ (architecture files), "
          "confirm.csv, hypervolume.csv, front.png, hypervolume.png, trials/ (each evaluation's stats.json and log), "
          "study.db (the Optuna study).", ""]
    return "\n".join(L)


def time_and_fidelity(run, done):
    """result.json's account of the time (per phase; evaluations and their seconds per fidelity)
    and of the screening's error against the target fidelity."""
    per = {}
    for t in done:
        fid = t.user_attrs.get("fidelity", TARGET)
        n, sec = per.get(fid, (0, 0.0))
        per[fid] = (n + 1, sec + run.evaluation(t)["wall_s"])
    return {"budget_s": run.clock.budget, "elapsed_s": round(run.clock.elapsed(), 3),
            "phases_s": {k: round(v, 3) for k, v in run.clock.phases.items()},
            "fidelities": {f: {"resolution": run.screen if f == SCREEN else run.space.resolution, "evaluations": n,
                               "evaluation_s": round(sec, 3)} for f, (n, sec) in per.items()},
            "fidelity_error": fidelity_error(run, run.screen) if run.screen else []}


def time_lines(run, done):
    r = time_and_fidelity(run, done)
    budget = f"a budget of {r['budget_s']:g} s; " if r["budget_s"] else ""
    phases = ", ".join(f"{k} {v:.1f} s" for k, v in r["phases_s"].items())
    L = ["## How the time went", "", f"{budget}{r['elapsed_s']:.1f} s in all: {phases}."]
    for f, x in r["fidelities"].items():
        res = x["resolution"] or "the scene's resolution"
        L += [f"- {f} ({res}): {x['evaluations']} evaluations, "
              f"{x['evaluation_s']:.1f} s of oprt runs ({x['evaluations'] / max(x['evaluation_s'], 1e-9) * run.jobs:.2f} "
              f"per second over {run.jobs} at once)."]
    if r["fidelity_error"]:
        L += ["", f"Screening at {run.screen} against the target fidelity {run.space.resolution}, on the "
                  f"{r['fidelity_error'][0]['pairs']} configurations priced at both (fidelity.csv; frame time and "
                  "energy scaled by the pixel ratio):", "",
              "| objective | Spearman | Kendall | mean relative error | largest |", "|---|---:|---:|---:|---:|"]
        L += [f"| {x['objective']} | {x['spearman']:.3f} | {x['kendall']:.3f} | {x['mean_rel_error_pct']:.1f} % | "
              f"{x['max_rel_error_pct']:.1f} % |" for x in r["fidelity_error"]]
    return L + [""]
