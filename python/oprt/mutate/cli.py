"""Mutation check: does the test suite notice when a rule of the model changes?

  scripts/mutate [--list tests/mutants.txt] [--only PATTERN] [--jobs N] [--narrow-only]
                 [--build-cmd CMD] [--test-cmd CMD] [--check] [--timeout S]

Applies one mutant at a time from the list (tests/mutants.txt: a file, an exact text that occurs
once in it, its replacement, the rule it stands for), rebuilds incrementally, runs the tests that
cover the mutated file first (the mutant's `tests:` or the list's `cover:` line for its path),
and the whole suite only when those all pass. The file is restored after every mutant, also
when the run is interrupted (SIGINT, SIGTERM) and, if the tool itself was killed, at the start of
the next run (a journal under the git directory holds the original bytes). Prints one row per
mutant (killed by which test, survived, equivalent, or not built) and the score:
killed / (mutants that built), where a survivor marked `equivalent:` in the list counts as
neither (reported beside the score).

A developer's check, like ../shared/checks/speed: not run by CI. --check only verifies that every
mutant's text occurs exactly once in its file (a ctest entry runs it, so a list that no longer
matches the code fails the suite). docs/reliability.md, "Mutation check".
"""
import argparse
import os
import re
import signal
import sys
import time

from .. import paths
from .mutants import check_mutant, fail, groups_for, parse_list
from .runner import Runner, first_error, recover


class Interrupted(Exception):
    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--list", default=os.path.join("tests", "mutants.txt"), help="mutant list (relative to --root)")
    p.add_argument("--root", default=paths.REPO, help="source tree the list's paths are relative to")
    p.add_argument("--build-dir", default="build")
    p.add_argument("--only", help="regular expression: run the mutants whose id, file or rule match")
    p.add_argument("--jobs", "-j", type=int, default=2, help="ctest -j and build -j (default 2)")
    p.add_argument("--timeout", type=int, default=300, help="seconds per test before ctest stops it")
    p.add_argument("--narrow-only", action="store_true",
                   help="a mutant the covering tests miss is reported survived without the whole suite")
    p.add_argument("--build-cmd", help="shell command instead of cmake --build (testing the tool)")
    p.add_argument("--test-cmd", help="shell command instead of ctest; fails = killed (testing the tool)")
    p.add_argument("--check", action="store_true", help="only check that every mutant applies")
    args = p.parse_args(argv)
    if args.jobs < 1:
        fail("--jobs: must be at least 1")
    root = os.path.abspath(args.root)
    list_path = os.path.join(root, args.list)
    cover, mutants = parse_list(list_path)
    if args.only:
        try:
            only = re.compile(args.only)
        except re.error as e:
            fail(f"--only: {e}")
        mutants = [m for m in mutants if only.search(m["id"]) or only.search(m["file"]) or only.search(m["rule"])]
        if not mutants:
            fail(f"--only: no mutant matches {args.only!r}")

    bad = []
    for m in mutants:
        _, _, err = check_mutant(m, root)
        if err:
            bad.append(f"{args.list}: line {m['line']}: {m['id']}: {err}")
    if args.check:
        for b in bad:
            print(b, file=sys.stderr, flush=True)
        covered = [m for m in mutants if groups_for(m, cover)]
        print(f"{len(mutants)} mutants, {len(mutants) - len(bad)} apply, {len(covered)} have covering tests, "
              f"{sum(1 for m in mutants if m.get('equivalent'))} marked equivalent")
        sys.exit(1 if bad else 0)
    if bad:
        for b in bad:
            print(b, file=sys.stderr)
        sys.exit(2)

    runner = Runner(args, root)
    recover(runner.journal, root)

    stopped = []

    def on_signal(signum, frame):
        if not stopped:  # the first signal stops the run; later ones find it stopping already
            stopped.append(signum)
            raise Interrupted(signum)
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)

    results = []
    interrupted = None
    width = max(len(m["id"]) for m in mutants)
    try:
        for i, m in enumerate(mutants, 1):
            original, mutated, _ = check_mutant(m, root)
            t0 = time.monotonic()
            outcome, detail = runner.mutate(m, original, mutated, cover)
            if outcome == "survived" and m.get("equivalent"):
                outcome, detail = "equivalent", m["equivalent"]
            results.append((m, outcome, detail))
            print(f"[{i}/{len(mutants)}] {m['id']:<{width}}  {outcome:<10} {detail}  ({time.monotonic() - t0:.0f} s)",
                  flush=True)
    except Interrupted as e:
        interrupted = e
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)

    report(results, width, len(mutants))
    if interrupted:
        print(f"mutate: stopped by {interrupted}; {len(results)} of {len(mutants)} mutants ran; "
              "the tree is restored", file=sys.stderr)
        if args.build_cmd is None:
            print(f"mutate: {args.build_dir}/ may still hold binaries built from a mutant: "
                  f"cmake --build {args.build_dir} rebuilds them (ccache hits)", file=sys.stderr)
        sys.exit(128 + interrupted.signum)
    if args.build_cmd is None:
        # The executables each mutant rebuilt still hold it: build them again from the restored
        # sources, so that build/ is what the tree says. (Interruptible again: nothing to restore.)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        status, out = runner.build([])
        if status != 0:
            print(f"mutate: rebuilding {args.build_dir}/ from the restored sources failed: {first_error(out)}",
                  file=sys.stderr)
            sys.exit(2)
    survivors = [r for r in results if r[1] == "survived"]
    sys.exit(1 if survivors else 0)


def report(results, width, total):
    print()
    print(f"{'mutant':<{width}}  {'outcome':<10} {'killing test / reason':<60} rule")
    for m, outcome, detail in results:
        print(f"{m['id']:<{width}}  {outcome:<10} {detail[:60]:<60} {m['rule']}")
    killed = sum(1 for r in results if r[1] == "killed")
    equivalent = sum(1 for r in results if r[1] == "equivalent")
    survived = sum(1 for r in results if r[1] == "survived")
    unbuilt = sum(1 for r in results if r[1] in ("not built", "error"))
    scored = killed + survived + equivalent
    print()
    if scored:
        print(f"score: {killed} of {scored} killed ({100.0 * killed / scored:.1f} %); "
              f"{equivalent} equivalent, {survived} survived not marked equivalent, {unbuilt} not built or not tested; "
              f"{len(results)} of {total} ran")
    else:
        print(f"score: no mutant built and ran ({unbuilt} not built or not tested; {len(results)} of {total} ran)")

