"""Write the paper's two test scenes (Kaeriyama et al., Fig. 5) as oprt-scene/1 files:

  scenes/paper_polygons.json  (a) 65,536 small triangles in 32 equal rigid groups of 2,048,
                              on a 4x4x2 grid, each group drifting and tumbling for 60 frames.
  scenes/paper_room.json      (b) an indoor room: 35,108 triangles in 32 rigid objects of very
                              unequal size and primitive count (walls of 2 triangles next to
                              finely tessellated vases and globes), a few of them animated.

Deterministic (fixed seeds, Python's Mersenne Twister, rounded output): running it again
rewrites byte-identical files. Meshes are `generate` recipes, so the files stay small; every
triangle count is computed here from the generators' closed formulas (model/scene/generate.h)
and asserted, and one object per scene absorbs the remainder so the totals match the paper.

Usage: scripts/make_paper_scenes [--out DIR]   (default: scenes/ next to scripts/)
"""

import argparse
import os

from .. import paths
from .mesh import write_scene
from .polygons import POLYGON_TRIANGLES, polygons
from .room import ROOM_TRIANGLES, room


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=paths.SCENES)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    for name, make, total in (("paper_polygons.json", polygons, POLYGON_TRIANGLES),
                              ("paper_room.json", room, ROOM_TRIANGLES)):
        scene = make()
        counts = sorted(o["_n"] for o in scene["objects"])
        size = write_scene(os.path.join(args.out, name), scene)
        print(f"{name}: {len(scene['objects'])} objects, {sum(counts)} triangles (expected {total}), "
              f"per object {counts[0]}..{counts[-1]}, {size} bytes")
