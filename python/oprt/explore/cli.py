"""Multi-objective design-space search over `oprt render` (docs/explore.md).

  scripts/explore SPACE.json --out DIR [--evaluations N] [--seed S] [--sampler nsga2|tpe]
                  [--jobs N] [--grid] [--slurm] [--storage URL|FILE.journal] [--oprt BINARY]

SPACE (`oprt-space/1`) names the parameters to search (architecture-file keys, dotted, and
`oprt render` options), two or three objectives among frame_time_s, energy_j and area_mm2, and
upper (or lower) bounds on any objective or per-frame stats.json figure. Optuna's NSGA-II or
TPE sampler, seeded, proposes configurations; each is priced by `oprt render --level analytic`;
at the end the Pareto-optimal ones are rendered again at `--level at`, and the search fails
loudly if the two levels differ by more than 1 %. The study lives in DIR (SQLite): the same
command resumes it after an interruption of any kind. `--grid` evaluates every point of a
space of choices. Outputs: DIR/evaluations.csv, pareto.csv, pareto/trial_NNNNN.json (an
architecture file per Pareto point), front.png, hypervolume.png, summary.md.

Exit status: 0 done, 1 a confirmation beyond 1 % or evaluations missing, 2 bad space or
command line, 128 + signal when interrupted. Needs Debian's python3-optuna and
python3-matplotlib (scripts/setup).

This module: the command line of scripts/explore (options, checks, a search from start to report).
"""
import argparse
import fcntl
import json
import os
import shlex
import signal
import sys
import time

from .. import paths, slurm
from ..files import atomic_json, atomic_write
from ..spec import SpecError
from .confirm import confirm, evaluate_references, reference_point
from .evaluate import Oprt
from .outputs import fmt, write_outputs
from .probe import check_constraint_keys, check_out_dir, probe_space
from .space import load_space
from .storage import import_optuna, load_reused
from .study import Run, pareto_trials
from .reuse import seed_study
from .fidelity import UNBOUNDED, Clock, parse_duration, screen_resolution
from .common import RUN_FORMAT, SpaceError, UsageError, grid_points


# ------------------------------------------------------------------------------------- Slurm
def slurm_script(script, args, out, storage, oprt_binary, tasks, sbatch):
    """The array job's text and the command that confirms and reports once every task has ended."""
    common = [script, os.path.abspath(args.space), "--out", out, "--storage", storage, "--oprt", oprt_binary,
              "--sampler", args.sampler, "--seed", str(args.seed)]
    amount = ["--grid"] if args.grid else ["--evaluations", str(args.evaluations)]
    cmd = common + ["--jobs", "1", "--worker"] + amount
    final = common + amount
    name = os.path.splitext(os.path.basename(args.space))[0]
    comments = [f"Slurm array job for the search {os.path.abspath(args.space)}: {tasks} tasks share one Optuna study",
                f"({storage}); each evaluates one configuration at a time until the study holds "
                + ("every grid point." if args.grid else f"{args.evaluations} evaluations."),
                "Written by scripts/explore --slurm; submit, then confirm and report once every task has ended:",
                f"  jid=$(sbatch --parsable {shlex.quote(os.path.join(out, 'explore.sbatch'))})",
                "  sbatch --dependency=afterany:$jid --wrap " + shlex.quote(" ".join(map(shlex.quote, final)))]
    return slurm.array_script(f"oprt-explore-{name}", comments, tasks, f"{out}/slurm", sbatch, cmd), final


# -------------------------------------------------------------------------------------- main
def parse_args(argv, doc):
    ap = argparse.ArgumentParser(prog="explore", description=doc.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="Space format, outputs and examples: docs/explore.md")
    ap.add_argument("space", metavar="SPACE.json", help="the design space (oprt-space/1)")
    ap.add_argument("--out", required=True, help="output folder: the study, its evaluations and reports")
    ap.add_argument("--evaluations", type=int, help="evaluations the study should hold (default 100, or as many as "
                                                    "--budget allows; --grid: every point)")
    ap.add_argument("--budget", metavar="TIME", help="the time the command may take (90s, 15m, 1h): the search "
                    "evaluates until 85 %% of it is spent, then confirms the front")
    ap.add_argument("--screen", metavar="WxH|none", help="screen configurations at this resolution first (default: "
                    "the space's divided by 4 per side), the promising ones then at the space's")
    ap.add_argument("--promote", type=float, default=0.25, metavar="FRACTION",
                    help="the share of the screened configurations priced at the space's resolution (default 0.25, "
                         "and every non-dominated one)")
    ap.add_argument("--seed", type=int, default=0, help="the sampler's seed (default 0): the same seed, the same search")
    ap.add_argument("--sampler", choices=("nsga2", "tpe", "portfolio"), default="nsga2",
                    help="Optuna's NSGA-II (default), TPE, or portfolio: a Latin-hypercube first generation, then NSGA-II")
    ap.add_argument("--jobs", "-j", type=int, default=len(os.sched_getaffinity(0)),
                    help="evaluations at once (default: the cores); with --slurm, the array's tasks")
    ap.add_argument("--group", type=int, default=8, metavar="N",
                    help="configurations per oprt process at the analytic level (oprt batch: the scene loaded, "
                         "its BVHs built once; default 8; 1: one oprt render each)")
    ap.add_argument("--grid", action="store_true", help="evaluate every point (every parameter a choice or fixed)")
    ap.add_argument("--slurm", action="store_true",
                    help="write DIR/explore.sbatch, a Slurm array job whose tasks share the study; run nothing")
    ap.add_argument("--sbatch", action="append", default=[], metavar="OPTION",
                    help="an extra #SBATCH line for --slurm, e.g. --sbatch=--time=02:00:00 (repeatable)")
    ap.add_argument("--storage", metavar="URL|FILE",
                    help="the study store: a database URL (postgresql://..., mysql://..., sqlite:///...) or a "
                         "journal file (FILE.journal; the default with --slurm); default DIR/study.db")
    ap.add_argument("--oprt", help="the oprt binary (default: $OPRT_BINARY, else build/testbench/oprt)")
    ap.add_argument("--timeout", type=float, default=3600, metavar="SECONDS",
                    help="an evaluation running longer fails (default 3600; 0: never)")
    ap.add_argument("--no-confirm", action="store_true",
                    help="skip the Pareto points' runs at --level at (a ground-truth grid, a measurement)")
    ap.add_argument("--reuse", metavar="DIR", action="append", default=[],
                    help="start from the evaluations of an earlier explore output or a sweep output (its aggregate.csv) "
                         "of the same scenes, frames and resolution: added to the study, not rendered again (repeatable)")
    ap.add_argument("--price-from", metavar="DIR", help=argparse.SUPPRESS)  # figures only (scripts/explore_target)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)  # a Slurm task: evaluate only
    ap.add_argument("--stale-after", type=float, default=600, help=argparse.SUPPRESS)
    ap.add_argument("--max-duplicates", type=int, default=1000, help=argparse.SUPPRESS)
    return ap, ap.parse_args(argv)


def main(argv=None, doc=__doc__, script=None):
    """scripts/explore: `doc` is its usage text (this module's), `script` its path (for the Slurm
    job's commands; default sys.argv[0]). Returns the exit status."""
    try:
        return explore(argv, doc, os.path.abspath(script or sys.argv[0]))
    except KeyboardInterrupt:  # before the search installs its own handler (checking the space)
        print("\nexplore: interrupted", file=sys.stderr)
        return 130


def check_options(a):
    """The command line and the space file (nothing run yet): (space, grid points or None)."""
    if a.jobs < 1:
        raise UsageError("--jobs must be at least 1")
    if a.group < 1:
        raise UsageError("--group must be at least 1")
    if a.evaluations is not None and a.evaluations < 1:
        raise UsageError("--evaluations must be at least 1")
    check_out_dir(a.out)
    if a.storage and "://" not in a.storage:
        path = a.storage[len("journal:"):] if a.storage.startswith("journal:") else a.storage
        if os.path.lexists(path) and not os.path.isfile(path):
            raise UsageError(f"--storage {a.storage}: not a regular file")
        check_out_dir(os.path.dirname(os.path.abspath(path)) or ".", "--storage")
    try:
        space = load_space(a.space)
        grid = grid_points(space, a.space) if a.grid else None
    except SpecError as e:
        raise SpaceError(a.space, "", str(e).split(": ", 1)[-1]) from None
    if a.grid and a.evaluations is not None and a.evaluations != len(grid):
        raise UsageError(f"--grid evaluates every one of the space's {len(grid)} points: leave out --evaluations")
    a.budget_s = parse_duration(a.budget) if a.budget else None
    if not 0 < a.promote <= 1:
        raise UsageError(f"--promote {a.promote:g}: expected a share above 0 and at most 1")
    a.screen_res = None if a.grid else screen_resolution(a.screen, space.resolution)
    a.evaluations = len(grid) if a.grid else (a.evaluations or (UNBOUNDED if a.budget_s else 100))
    return space, grid


def check_manifest(a, space, out):
    """The output folder's explore.json (None for a new search), with a.storage resolved; refuses
    a folder that holds another search."""
    manifest_file = os.path.join(out, "explore.json")
    manifest = None
    if os.path.isfile(manifest_file):
        with open(manifest_file) as f:
            manifest = json.load(f)
    if a.storage is None and a.slurm:
        a.storage = os.path.join(out, "study.journal")
    if a.storage is None and manifest and manifest.get("storage"):
        a.storage = manifest["storage"]
    if a.storage and "://" not in a.storage:
        a.storage = os.path.abspath(a.storage[len("journal:"):] if a.storage.startswith("journal:") else a.storage)
    if manifest:
        for key, mine in (("space_hash", space.grid_hash if a.grid else space.hash), ("sampler", "grid" if a.grid else a.sampler),
                          ("seed", a.seed), ("storage", a.storage), ("screen", a.screen_res)):
            if manifest.get(key) != mine:
                what = {"space_hash": f"the space {manifest.get('space')} as it was then"}.get(
                    key, f"{key} {manifest.get(key)}")
                raise UsageError(f"--out {a.out}: holds a search of {what}, not this one: rerun with the same "
                                 "space and options to resume it, or give another --out")
    return manifest


def prepare(a):
    """Everything checked before the output folder is touched: (space, grid, binary, Oprt, out,
    manifest, optuna). Raises SpaceError, SpecError or UsageError."""
    space, grid = check_options(a)
    optuna = import_optuna()
    binary = os.path.abspath(paths.oprt_binary(a.oprt))
    if not (os.path.isfile(binary) and os.access(binary, os.X_OK)):
        raise UsageError(f"no oprt binary at {binary} (build it with scripts/build, or pass --oprt)")
    oprt = Oprt(binary, space)
    out = os.path.abspath(a.out)
    manifest = check_manifest(a, space, out)
    keys = probe_space(space, oprt, max(1, a.jobs), a.space) if not (a.worker and manifest) else set()
    if not (a.worker and manifest):
        check_constraint_keys(space, keys, a.space)
    return space, grid, binary, oprt, out, manifest, optuna


def explore(argv, doc, script):
    _, a = parse_args(argv, doc)
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    try:
        space, grid, binary, oprt, out, manifest, optuna = prepare(a)
    except (SpaceError, SpecError, UsageError) as e:
        print(f"explore: {e}", file=sys.stderr)
        return 2
    os.makedirs(out, exist_ok=True)
    lock = open(os.path.join(out, "explore.lock"), "a")
    if not a.worker:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            print(f"explore: another explore is running in {a.out}", file=sys.stderr)
            return 2
    if not manifest:
        manifest = {"format": RUN_FORMAT, "space": space.file, "space_hash": space.grid_hash if a.grid else space.hash,
                    "eval_hash": space.eval_hash,
                    "sampler": "grid" if a.grid else a.sampler, "seed": a.seed, "storage": a.storage,
                    "screen": a.screen_res,
                    "oprt_flags_folded": None}
        atomic_json(os.path.join(out, "explore.json"), manifest)
    run = Run(a, space, oprt, optuna)
    run.clock = Clock(a.budget_s)
    run.screen = a.screen_res
    run.rung = max(2 * a.jobs, 10)
    run.grid = grid
    run.target = a.evaluations
    stopping = []

    def on_signal(signum, _frame):
        run.stop_signal = signum
        stopping.append(signum)
        if len(stopping) == 1:
            print(f"\nexplore: {signal.Signals(signum).name}: stopping (the evaluations in flight are lost and "
                  "queued again); run the same command to resume", file=sys.stderr)

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    try:
        return search(run, a, script, binary, out)
    except (SpaceError, UsageError) as e:
        print(f"explore: {e}", file=sys.stderr)
        return 2
    finally:
        lock.close()


def open_search(run, a, script, binary, out):
    """Opens (or resumes) the study and queues what it starts with; with --slurm, writes the
    array job and returns 0 (nothing else to do), else None."""
    shared = a.storage is not None
    run.open_study(create=True)
    for folder in a.reuse + ([a.price_from] if a.price_from else []):
        if os.path.isfile(os.path.join(folder, "explore.json")):
            run.reused.update(load_reused(run.optuna, folder, run.space))
    if not a.worker:
        run.recover(shared=shared)
    if run.space.start and not a.grid and not a.worker and not run.trials():
        for point in run.space.start:
            run.study.enqueue_trial(point, user_attrs={"start": True})
    for folder in a.reuse if not a.worker else []:
        n = seed_study(run, folder)
        print(f"explore: --reuse {folder}: {n} evaluated configurations of this space added to the study", file=sys.stderr)
    if a.grid and not a.worker:
        queued = run.enqueue_grid()
        if queued:
            print(f"explore: {queued} grid points queued", file=sys.stderr)
    if not shared and not a.worker and not a.slurm:
        run.go_in_memory()
    if a.slurm:
        os.makedirs(os.path.join(out, "slurm"), exist_ok=True)
        text, final = slurm_script(script, a, out, a.storage, binary, a.jobs, a.sbatch)
        path = os.path.join(out, "explore.sbatch")
        atomic_write(path, text)
        os.chmod(path, 0o755)
        print(f"explore: wrote {path}: {a.jobs} array tasks sharing {a.storage}; submit it with sbatch, then run "
              f"(or submit after it): {' '.join(map(shlex.quote, final))}", file=sys.stderr)
        return 0
    return None


def search(run, a, script, binary, out):
    """The search from the study's opening to the report; returns the exit status."""
    status = open_search(run, a, script, binary, out)
    if status is not None:
        return status
    references = None
    t = time.time()
    if not a.worker:
        references = evaluate_references(run)
        run.clock.add("references", time.time() - t)
        if references is None:
            return 128 + run.stop_signal
        run.reference_point = reference_point(run.space, references)
    else:
        run.reference_point = {o: 1.0 for o in run.space.objectives}
    done = len(run.done())
    if done < run.target:
        what = f"{done} of {run.target} evaluations done" if run.target < UNBOUNDED else f"{done} evaluations done"
        limit = f", for {a.budget}" if a.budget else ""
        screen = f", screened at {run.screen} first" if run.screen else ""
        print(f"explore: {what}; evaluating{limit}, {a.jobs} at a time (oprt --level analytic{screen}, "
              f"{run.threads} thread{'s' if run.threads > 1 else ''} each)", file=sys.stderr)
    t = time.time()
    note = run.run(shared=a.storage is not None)
    run.clock.add("search", time.time() - t)
    if run.stop_signal:
        run.write_evaluations()
        print(f"explore: interrupted with {len(run.done())} of {run.target} evaluations done", file=sys.stderr)
        return 128 + run.stop_signal
    if a.worker:
        return 0
    return report(run, a, references, note)


def report(run, a, references, note):
    """Confirms the front at `at`, writes the outputs; returns the exit status."""
    done = run.done()
    front = pareto_trials(run, [t for t in run.final(done) if run.evaluation(t)["outcome"] == "complete"])
    confirmed = None
    if not a.no_confirm and front:
        print(f"explore: confirming the {len(front)} Pareto configurations at --level at", file=sys.stderr)
        t = time.time()
        confirmed = confirm(run, front)
        run.clock.add("confirmation", time.time() - t)
        if confirmed is None:
            return 128 + run.stop_signal
    front = write_outputs(run, references, confirmed, note)
    print(f"explore: {len(done)} evaluations, {len(front)} Pareto-optimal; report in {os.path.join(a.out, 'summary.md')}",
          file=sys.stderr)
    status = 0
    if len(done) < run.target and not (note and ("every one is evaluated" in note or "budget" in note)):
        print(f"explore: only {len(done)} of {run.target} evaluations: {note or 'run the same command again'}",
              file=sys.stderr)
        status = 1
    bad = [r for r in confirmed or [] if r.get("state") != "confirmed" or
           max(r["frame_time_s_error_pct"], r["energy_j_error_pct"]) > 1.0]
    if bad:
        print("explore: CONFIRMATION FAILED: the analytic level and the timing reference (--level at) differ "
              "by more than 1 % on these Pareto configurations:", file=sys.stderr)
        for r in bad:
            if r.get("state") != "confirmed":
                print(f"explore:   trial {r['trial']}: the at run failed: {r.get('reason')}", file=sys.stderr)
            else:
                print(f"explore:   trial {r['trial']}: frame time {fmt('frame_time_s', r['frame_time_s_analytic'])} "
                      f"analytic, {fmt('frame_time_s', r['frame_time_s_at'])} at ({r['frame_time_s_error_pct']:.3f} %); "
                      f"energy {r['energy_j_error_pct']:.3f} %", file=sys.stderr)
        print("explore: the front is not trustworthy at the analytic level: see confirm.csv", file=sys.stderr)
        status = 1
    return status
