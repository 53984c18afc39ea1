"""What tracing costs on one frame: `oprt render` without a trace, with --vcd FILE.vcd, with
--vcd FILE.fst and with --timeline FILE.json, each run REPEAT times in turn (so that a busy
machine slows them alike). Prints a Markdown table (docs/results.md): per configuration the
median wall time; each run's wall time over the untraced run just before it, and their
median; user and system CPU time, and the median ratio of their sum to the untraced run's;
peak resident memory (wait4's rusage) and its excess over the untraced run; the trace's size;
and the load average before and after.

  scripts/trace_cost [--oprt PATH] [--repeat N] [--resolution WxH] [--threads N]

The frame is the room's frame 0 under the paper's ideal assumptions at `at`, 256x256 unless
--resolution says otherwise. Not a test: wall times depend on the machine and its load."""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

from .. import paths


def run(oprt, args):
    t0 = time.monotonic()
    p = subprocess.Popen([oprt] + args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    err = p.stderr.read().decode()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    if status != 0:
        sys.exit(f"trace_cost: oprt {' '.join(args)} failed (status {status}):\n{err}")
    return wall, usage.ru_utime, usage.ru_stime, usage.ru_maxrss * 1024


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--oprt", default=paths.BUILD_OPRT)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--resolution", default="")
    ap.add_argument("--threads", default="")
    a = ap.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="oprt_trace_cost_")
    base = ["render", os.path.join(paths.SCENES, "paper_room.json"), "--arch",
            os.path.join(paths.ARCH, "paper.json"), "--frames", "0", "--level", "at", "--no-progress"]
    if a.resolution:
        base += ["--resolution", a.resolution]
    if a.threads:
        base += ["--threads", a.threads]
    configs = [("no trace", [], None),
               ("--vcd trace.vcd", ["--vcd", os.path.join(tmp, "trace.vcd")], "trace.vcd"),
               ("--vcd trace.fst", ["--vcd", os.path.join(tmp, "trace.fst")], "trace.fst"),
               ("--timeline trace.json", ["--timeline", os.path.join(tmp, "trace.json")], "trace.json")]
    load_before = os.getloadavg()
    results = {name: [] for name, _, _ in configs}
    for _ in range(a.repeat):
        for name, extra, _ in configs:
            results[name].append(run(a.oprt, base + ["--out", os.path.join(tmp, "out")] + extra))
    load_after = os.getloadavg()
    median = {name: [statistics.median(r[i] for r in rs) for i in range(4)] for name, rs in results.items()}
    m0 = median["no trace"][3]
    print(f"`{' '.join(['oprt'] + base[:1] + ['scenes/paper_room.json'] + base[2:3] + ['testbench/arch/paper.json'] + base[4:])}`"
          f" + the trace option; median of {a.repeat} runs each, in turn. Load average (1, 5, 15 min) "
          f"{'/'.join(f'{x:.1f}' for x in load_before)} before, {'/'.join(f'{x:.1f}' for x in load_after)} after, "
          f"on {os.cpu_count()} cores.\n")
    print("| trace | wall s | wall ratio | wall ratios of the runs | user s | sys s | CPU ratio | peak RSS MB "
          "| over untraced MB | file MB |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, _, file in configs:
        w, u, s, m = median[name]
        ratios = [r[0] / n[0] for r, n in zip(results[name], results["no trace"])]  # each run against the one before it
        cpu = statistics.median((r[1] + r[2]) / (n[1] + n[2]) for r, n in zip(results[name], results["no trace"]))
        size = f"{os.path.getsize(os.path.join(tmp, file)) / 1e6:.1f}" if file else ""
        print(f"| {name} | {w:.2f} | {statistics.median(ratios):.2f} | {', '.join(f'{r:.2f}' for r in ratios)} "
              f"| {u:.2f} | {s:.2f} | {cpu:.2f} | {m / 1e6:.0f} | {(m - m0) / 1e6:+.0f} | {size} |")
