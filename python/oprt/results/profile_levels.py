"""Where one run of oprt spends its time, by category, in percent of perf samples.

Usage: scripts/profile_levels OPRT_BINARY ARGS...   e.g.
  scripts/profile_levels build/testbench/oprt render scenes/paper_room.json --arch testbench/arch/paper.json \
      --frames 0 --threads 1 --level analytic --no-progress --out /tmp/p
Needs perf (linux-perf). Categories are matched on symbol and library names, first match wins.
"""
import collections
import os
import re
import subprocess
import sys
import tempfile

RULES = [
    ("page faults and kernel", r"\[kernel|\[k\]"),
    ("ray kernels (SIMD tests)", r"simd|sphere_hits|in_sphere|hit_box|slab|moller|watertight|triangle"),
    ("tracing (traversal, shading)", r"trace_pixel|trace_nearest|trace_any|Shader|surface_point|offset_origin|traverse|top_|bvh"),
    ("functional trace records", r"Recorder|trace_functional|copy_chunk|index_units|assemble|Chunk|emplace_back|_M_realloc|_M_default_append"),
    ("analytic timing", r"Analytic|GppWork|PopTimes|Calendar|occupancy"),
    ("SystemC kernel", r"sc_core|sc_cor|libsystemc|tlm_utils|tlm::"),
    ("TLM modules", r"oprt::hw::(Bus|Gpp|RayFifo|SerialUnit|PipelinedUnit|IntersectionUnit|ObjectMemory|Dram|LocalClock)"),
    ("memory model and caches", r"ObjectMemoryModel|Cache|MissWindow|visit_stream|cached_visit"),
    ("image output", r"stbi|deflate|zlib|Imf|Iex|pow|exr|png|libz|libOpenEXR"),
    ("malloc", r"malloc|free|_int_|cfree|operator new|operator delete"),
]


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 1:
        sys.exit(__doc__)
    env = dict(os.environ, SYSTEMC_DISABLE_COPYRIGHT_MESSAGE="1")
    with tempfile.TemporaryDirectory() as d:
        data = os.path.join(d, "perf.data")
        subprocess.run(["perf", "record", "-F", "4000", "-o", data] + argv, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, env=env)
        out = subprocess.run(["perf", "report", "-i", data, "--no-children", "--sort", "dso,symbol", "--stdio"],
                             capture_output=True, text=True).stdout
    cats = collections.Counter()
    for line in out.splitlines():
        m = re.match(r"\s+([0-9.]+)%\s+(\S+)\s+(.*)", line)
        if not m:
            continue
        p = float(m.group(1))
        text = m.group(2) + " " + m.group(3)
        for name, rx in RULES:
            if re.search(rx, text):
                cats[name] += p
                break
        else:
            cats["other"] += p
    for name, p in cats.most_common():
        print(f"{p:6.1f} %  {name}")
