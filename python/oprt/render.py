"""Running `oprt render` (and `oprt reference`): one render to its stats, or a child process that ends with its parent.

A child started with `popen` (or with `preexec_fn=die_with_parent()`) asks Linux for a
parent-death signal (prctl PR_SET_PDEATHSIG): when the process that started it ends, however it
ends (kill -9 included), the kernel sends the child that signal. The request is made in the child
between fork and exec, so a parent that died in between would be missed: the child then checks
that its parent is still the process that forked it, and signals itself if not.
"""
import os
import signal
import subprocess
import sys
import time

from . import paths
from .stats import read_stats

PR_SET_PDEATHSIG = 1  # linux/prctl.h


def child_env(extra=None):
    """The environment oprt runs in: this one, without SystemC's banner."""
    return dict(os.environ, SYSTEMC_DISABLE_COPYRIGHT_MESSAGE="1", **(extra or {}))


def die_with_parent(sig=signal.SIGKILL, parent=None):
    """A preexec_fn: the child gets `sig` when the process that forks it ends. Call it in the
    parent (it notes the parent's pid, or takes `parent`), pass the result as Popen's preexec_fn."""
    parent = parent or os.getpid()

    def in_child():
        try:
            import ctypes
            ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(sig))
        except Exception:  # not Linux: the child outlives a killed parent
            return
        if os.getppid() != parent:  # the parent ended before the request: act as if signalled
            os.kill(os.getpid(), sig)

    return in_child


def popen(cmd, sig=signal.SIGKILL, **kwargs):
    """subprocess.Popen of a child that ends with this process (signal `sig`, default SIGKILL)."""
    return subprocess.Popen(cmd, preexec_fn=die_with_parent(sig), **kwargs)


def command(args, out, oprt=None):
    """The command line of `oprt render ARGS --out OUT --no-progress`."""
    return [paths.oprt_binary(oprt), "render", *map(str, args), "--out", str(out), "--no-progress"]


def run(cmd, who):
    """Runs `cmd` and returns its wall seconds; on failure the script ends with a message naming
    `who`, the command, its exit status and output."""
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"{who}: {' '.join(cmd)} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
    return wall


def render(args, out, oprt=None, who="oprt", timed=False):
    """Runs `oprt render ARGS --out OUT --no-progress` and returns its stats.json as a dict
    (with timed, the pair (stats, wall seconds)). On failure the script ends with a message
    naming `who`, the command, its exit status and output."""
    os.makedirs(out, exist_ok=True)
    wall = run(command(args, out, oprt), who)
    stats = read_stats(out)
    return (stats, wall) if timed else stats


def reference(args, out, oprt=None, who="oprt"):
    """Runs `oprt reference ARGS --out OUT` (the untimed renderer: frame_NNNN.exr and .png) and
    returns its reference.json as a dict; on failure ends the script as `render` does."""
    os.makedirs(out, exist_ok=True)
    run([paths.oprt_binary(oprt), "reference", *map(str, args), "--out", str(out)], who)
    return read_stats(os.path.join(out, "reference.json"))


def stop(proc, grace=10):
    """Ends a child: SIGTERM, then SIGKILL if it is still running after `grace` seconds."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(grace)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def script_arguments(doc, name, **defaults):
    """A result script's argument parser: its docstring as help, --oprt (default: the build's
    oprt), --out (default out/NAME in the repository) and an option per keyword, with that
    default (kitchen_resolution="256x192": --kitchen-resolution)."""
    import argparse
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--oprt", default=paths.BUILD_OPRT)
    ap.add_argument("--out", default=os.path.join(paths.REPO, "out", name))
    for option, default in defaults.items():
        ap.add_argument("--" + option.replace("_", "-"), default=default)
    return ap


def scenes_present(cases, who):
    """The cases (tuples: a name, a scene file, ...) whose scene file exists; the others are
    said to be skipped on stderr (the BART scenes live outside the repository)."""
    for case in cases:
        if os.path.isfile(case[1]):
            yield case
        else:
            print(f"{who}: {case[1]} not found: {case[0]} skipped", file=sys.stderr)


def chosen_scenes(text, known, who):
    """The scene names of a comma-separated --scenes value; the script ends naming any that is
    not among `known`."""
    wanted = text.split(",")
    unknown = set(wanted) - set(known)
    if unknown:
        sys.exit(f"{who}: --scenes: unknown {', '.join(sorted(unknown))} (known: {', '.join(known)})")
    return wanted
