#!/usr/bin/env bash
# Issue 32: oprt as a library. Installs this build into a fresh prefix, builds
# examples/platform outside the tree against the installed CMake package (find_package(oprt))
# and again with pkg-config (oprt.pc), runs both on paper_room at 32x32 with 4 KiB object
# memories (caches, so every unit's misses leave the engine through its memory port), and
# checks:
#  - the image is the reference renderer's (oprt reference, the installed command), byte for
#    byte and by `oprt compare` (no id mismatch, colour RMSE 0, Z error 0);
#  - the platform's own memory served every fill: as many as the misses `oprt render` counts
#    for the same architecture with its own DRAM (stats.json, per unit memory.misses), and
#    their bytes (memory.dram_bytes); a unit's misses are those of its access sequence, not of
#    the memory's latency (the platform's is 50 cycles, oprt's DRAM 40 + the transfer).
# And (issue 40) the Python package installed into the same prefix: Debian's Python, started
# outside the checkout with only the prefix's folder on its path, imports oprt from the prefix,
# whose default oprt binary is the prefix's own command; a known hypervolume and an 8x8 render
# through that command give their hand-computed figures.
#   test_platform.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -euo pipefail
src=$1 build=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
export SYSTEMC_DISABLE_COPYRIGHT_MESSAGE=1
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$src/examples/platform" -B "$work/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_FLAGS=-Werror \
  "${launcher[@]}" >/dev/null
cmake --build "$work/build"

scene=$src/scenes/paper_room.json
echo '{"format": "oprt-arch/1", "ius": 8, "memory": {"sram_bytes": "4K"}}' >"$work/arch.json"
"$prefix/bin/oprt" reference "$scene" --frames 0 --resolution 32x32 --out "$work/reference" >/dev/null
"$prefix/bin/oprt" render "$scene" --arch "$work/arch.json" --frames 0 --resolution 32x32 --no-progress \
  --out "$work/render" >/dev/null
read -r misses bytes < <(/usr/bin/python3 -c '
import json, sys
f = json.load(open(sys.argv[1]))["frames"][0]
print(sum(u["memory"]["misses"] for u in f["ius"]), sum(u["memory"]["dram_bytes"] for u in f["ius"]))' \
  "$work/render/stats.json")
echo "oprt render, its own DRAM: $misses misses, $bytes bytes"
[ "$misses" -gt 0 ] || { echo "FAIL: the architecture makes no cache miss: nothing would reach the port"; exit 1; }

check() {  # check NAME PLATFORM_BINARY
  local out
  out=$("$2" "$scene" "$work/arch.json" 32x32 "$work/$1")
  echo "$1: $out"
  grep -q "memory served $misses fills ($bytes bytes)" <<<"$out" ||
    { echo "FAIL: $1: its memory did not serve the $misses fills ($bytes bytes) of the misses"; exit 1; }
  cmp "$work/$1/frame_0000.exr" "$work/reference/frame_0000.exr" ||
    { echo "FAIL: $1: the image differs from the reference's"; exit 1; }
  "$prefix/bin/oprt" compare "$work/$1/frame_0000.exr" "$work/reference/frame_0000.exr" >"$work/$1/compare.json"
  /usr/bin/python3 -c '
import json, sys
c = json.load(open(sys.argv[1]))
bad = {k: c[k] for k in ("id_mismatches", "color_rmse", "max_rel_z") if c[k] != 0}
sys.exit(f"FAIL: oprt compare: {bad}" if bad or c["pixels"] != 1024 else 0)' "$work/$1/compare.json"
}
check cmake "$work/build/platform"

# The same source through oprt.pc.
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
# shellcheck disable=SC2046  # pkg-config's flags are words
${CXX:-c++} -Wall -Wextra -Werror "$src/examples/platform/platform.cpp" $(pkg-config --cflags --libs oprt) \
  -o "$work/platform_pc"
check pkg-config "$work/platform_pc"
echo "ok: examples/platform from the installed package renders the reference's image through its own memory"

site=$prefix/lib/python3/dist-packages
[ -f "$site/oprt/__init__.py" ] || { echo "FAIL: cmake --install put no Python package oprt into $site"; exit 1; }
(cd / && env -u OPRT_BINARY -u PYTHONHOME PYTHONPATH="$site" /usr/bin/python3 -s - "$prefix" "$src" "$scene" \
  "$work/python") <<'EOF'
import os, sys
prefix, src, scene, out = sys.argv[1:]
import oprt
from oprt import pareto, paths, render
where = os.path.realpath(oprt.__file__)
if not where.startswith(os.path.realpath(prefix) + os.sep):
    sys.exit(f"FAIL: import oprt found {where}, not the prefix's package")
if any(os.path.realpath(p or ".").startswith(os.path.join(os.path.realpath(src), "python")) for p in sys.path):
    sys.exit(f"FAIL: the checkout's python/ is on the path: {sys.path}")
binary = paths.oprt_binary()
if binary != os.path.join(prefix, "bin", "oprt"):
    sys.exit(f"FAIL: the installed package runs {binary}, not {prefix}/bin/oprt")
# (1,3), (2,2), (3,1) below (4,4): columns of 1, 2 and 3 unit squares.
hv = pareto.hypervolume([(1, 3), (2, 2), (3, 1)], (4, 4))
if hv != 6.0:
    sys.exit(f"FAIL: hypervolume {hv}, expected 6")
rays = render.render([scene, "--frames", "0", "--resolution", "8x8"], out)["frames"][0]["rays"]
if rays["primary"] != 64:
    sys.exit(f"FAIL: rays {rays}: expected 8x8 = 64 primary rays")
print(f"python: import oprt from {os.path.dirname(where)}, runs {binary}, hypervolume {hv:g}, 64 primary rays")
EOF
echo "ok: the installed Python package imports from the prefix and runs the prefix's oprt"
