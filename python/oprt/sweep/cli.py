"""Architecture-exploration sweeps over `oprt render` (docs/sweeps.md).

  scripts/sweep SPEC [--out DIR] [--jobs N]   run every point not yet done, then aggregate
  scripts/sweep SPEC --aggregate-only         aggregate the points that are done
  scripts/sweep SPEC --dry-run                list the points and their commands, run nothing
  scripts/sweep SPEC --point I                run point I only (one Slurm array task)
  scripts/sweep SPEC --slurm FILE             write a Slurm array job, one task per point

Numbers (counts, byte counts such as "64K", times such as "10 ns") are read by oprt itself:
before anything runs, every point is checked with `oprt render ... --check` (its files, its
numbers, its outputs and its memory), and a refusal is reported at the SPEC's place.

Every point is one `oprt render` process in its own directory OUT/points/<scene>-<hash>, where
the hash is that of the point's parameters (so a point keeps its directory when the SPEC is
rearranged). A point is finished when its `done.json` exists; it is written atomically after
a successful run only. Anything else in a point's directory is from an interrupted or failed
run: the directory is cleaned and the point rerun. Exit status: 0 all points done, 1 some
point failed or is not done yet, 2 bad SPEC or command line.
Standard library only.
"""
import argparse
import fcntl
import os
import shlex
import signal
import sys
import time

from .. import paths, slurm
from ..spec import SpecError
from ..values import fmt_time
from .aggregate import aggregate
from .points import expansion_hash, label, load_spec, varied
from .run import check_outputs, check_points, command, is_done, run_points


def slurm_script(me, spec_file, out, oprt, points, sbatch):
    """The array job's text: `me` (this command's path) runs one point per task."""
    name = os.path.splitext(os.path.basename(spec_file))[0]
    args = [me, os.path.abspath(spec_file), "--out", os.path.abspath(out), "--oprt", os.path.abspath(oprt),
            "--expect", expansion_hash(points)]
    comments = [f"Slurm array job for the sweep {os.path.abspath(spec_file)}: {len(points)} points, one array task each.",
                "Written by scripts/sweep --slurm; submit with:  sbatch THIS_FILE",
                "When every task has ended, aggregate with:",
                "  " + " ".join(map(shlex.quote, args[:4])) + " --aggregate-only"]
    return slurm.array_script(f"oprt-sweep-{name}", comments, len(points), f"{os.path.abspath(out)}/slurm", sbatch, args,
                              tail='--point "$SLURM_ARRAY_TASK_ID"')


# ---------------------------------------------------------------------------------------- main
def main(argv=None, script=None):
    """scripts/sweep (`script`: its path, default sys.argv[0], for the Slurm job's command).
    Returns the exit status."""
    ap = argparse.ArgumentParser(prog="sweep", description=__doc__.rsplit("\n", 2)[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="SPEC format and examples: docs/sweeps.md")
    ap.add_argument("spec", metavar="SPEC", help="sweep specification (JSON, oprt-sweep/1)")
    ap.add_argument("--out", help="output directory (default: out/sweeps/<SPEC name>)")
    ap.add_argument("--jobs", "-j", type=int, default=len(os.sched_getaffinity(0)),
                    help="points run at once (default: the cores this process may use)")
    ap.add_argument("--oprt", help="the oprt binary (default: $OPRT_BINARY, else build/testbench/oprt)")
    ap.add_argument("--aggregate-only", action="store_true", help="run nothing; aggregate the finished points")
    ap.add_argument("--dry-run", action="store_true", help="print the points and their commands; run nothing")
    ap.add_argument("--point", type=int, metavar="I", help="run point I only (0-based; for Slurm array tasks)")
    ap.add_argument("--slurm", metavar="FILE", help="write a Slurm array-job script for the sweep; run nothing")
    ap.add_argument("--sbatch", action="append", default=[], metavar="OPTION",
                    help='extra #SBATCH line for --slurm, e.g. --sbatch=--time=00:30:00 (repeatable)')
    ap.add_argument("--expect", metavar="HASH", help=argparse.SUPPRESS)  # the Slurm script's guard
    a = ap.parse_args(argv)
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `sweep SPEC --dry-run | head` ends quietly

    try:
        spec, points = load_spec(a.spec)
    except SpecError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return 2
    if a.expect and a.expect != expansion_hash(points):
        print(f"sweep: {a.spec}: the SPEC has changed since the Slurm script was written: write it again", file=sys.stderr)
        return 2
    if a.jobs < 1:
        ap.error("--jobs must be at least 1")
    if a.point is not None and not 0 <= a.point < len(points):
        print(f"sweep: {a.spec}: --point {a.point}: the sweep has points 0..{len(points) - 1}", file=sys.stderr)
        return 2
    out = a.out or os.path.join("out", "sweeps", os.path.splitext(os.path.basename(a.spec))[0])
    oprt = os.path.abspath(paths.oprt_binary(a.oprt))
    names = varied(points)
    if not a.aggregate_only and not a.dry_run and not (os.path.isfile(oprt) and os.access(oprt, os.X_OK)):
        print(f"sweep: no oprt binary at {oprt} (build it with scripts/build, or pass --oprt)", file=sys.stderr)
        return 2

    try:
        if not a.dry_run:
            check_outputs(out, a.slurm)
        if not a.aggregate_only and not a.dry_run and not a.slurm:
            check_points(a.spec, oprt, out, points, range(len(points)) if a.point is None else [a.point], a.jobs)
    except SpecError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return 2
    if a.slurm:
        os.makedirs(os.path.join(out, "slurm"), exist_ok=True)
        with open(a.slurm, "w") as f:
            f.write(slurm_script(os.path.abspath(script or sys.argv[0]), a.spec, out, oprt, points, a.sbatch))
        os.chmod(a.slurm, 0o755)
        print(f"sweep: wrote {a.slurm}: {len(points)} array tasks; submit with: sbatch {a.slurm}", file=sys.stderr)
        return 0
    chosen = range(len(points)) if a.point is None else [a.point]
    if a.dry_run:
        for i in chosen:
            p = points[i]
            state = "done" if is_done(out, p) else "to run"
            print(f"point {i} {p['dir']} [{state}] {label(p, names)}: "
                  + " ".join(map(shlex.quote, command(oprt, p, os.path.join(out, "points", p["dir"])))))
        return 0
    os.makedirs(out, exist_ok=True)
    if a.aggregate_only:
        return 1 if aggregate(out, points, names) else 0
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # stop the running points, as on Ctrl-C
    if a.point is not None:
        return 1 if run_points(out, oprt, points, chosen, 1, names) else 0

    with open(os.path.join(out, "sweep.lock"), "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            print(f"sweep: another sweep is running in {out}", file=sys.stderr)
            return 2
        try:
            t0 = time.time()
            failed = run_points(out, oprt, points, chosen, a.jobs, names)
        except KeyboardInterrupt:
            print("\nsweep: interrupted; run the same command again to resume", file=sys.stderr)
            return 130
        print(f"sweep: ran in {fmt_time(time.time() - t0)}", file=sys.stderr)
        missing = aggregate(out, points, names)
    return 1 if failed or missing else 0

