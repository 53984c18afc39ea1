"""A GTKWave screenshot of a frame's trace, for the README: renders the room's frame 0 at
256x256 under the paper's assumptions with --vcd trace.fst (four units, their state and FIFO
occupancy, and the GPP), opens the save file oprt wrote in GTKWave under Xvfb, zooms to the
whole frame, and grabs the screen (xwd), saved as PNG.

  scripts/waveform_shot [--oprt PATH] [--out docs/plots/waveform_gtkwave.png] [--units 0,12,16,31]

Needs Debian's gtkwave, xvfb and x11-apps (scripts/setup)."""
import argparse
import os
import subprocess
import sys
import tempfile

from .. import paths, plots
plots.require("waveform", "matplotlib", "numpy")
plt = plots.pyplot("waveform")
import numpy as np

WIDTH, HEIGHT = 1400, 760


def read_xwd(path):
    """An X window dump (ZPixmap, 24 or 32 bits per pixel, as Xvfb's root window) as RGB."""
    with open(path, "rb") as f:
        data = f.read()
    h = np.frombuffer(data[:100], dtype=">u4")
    header_size, pixmap_format, byte_order, bpp, bytes_per_line = h[0], h[2], h[7], h[11], h[12]
    width, height, ncolors = h[4], h[5], h[19]
    if pixmap_format != 2 or bpp not in (24, 32):
        sys.exit(f"waveform_shot: unexpected window dump (format {pixmap_format}, {bpp} bits per pixel)")
    start = int(header_size + 12 * ncolors)
    rows = np.frombuffer(data[start:start + int(bytes_per_line * height)], dtype=np.uint8)
    rows = rows.reshape(int(height), int(bytes_per_line))[:, :int(width * bpp // 8)]
    px = rows.reshape(int(height), int(width), int(bpp // 8))
    if byte_order == 0:  # least significant byte first: B, G, R
        return px[:, :, 2::-1] if bpp == 24 else px[:, :, [2, 1, 0]]
    return px[:, :, 1:4] if bpp == 32 else px


def main(argv=None):
    # GTKWave, Xvfb and xwd: installed on first use.
    subprocess.run([os.path.join(paths.REPO, "scripts", "setup"), "waveform"], check=True)
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--oprt", default=paths.BUILD_OPRT)
    ap.add_argument("--out", default=os.path.join(paths.REPO, "docs", "plots", "waveform_gtkwave.png"))
    ap.add_argument("--units", default="0,12,16,31", help="--trace-units (default: the lightest to the busiest)")
    a = ap.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="oprt_waveform_shot_")
    trace = os.path.join(tmp, "trace.fst")
    cmd = [a.oprt, "render", os.path.join(paths.SCENES, "paper_room.json"), "--arch",
           os.path.join(paths.ARCH, "paper.json"), "--frames", "0", "--no-progress",
           "--out", os.path.join(tmp, "out"), "--vcd", trace, "--trace-units", a.units,
           "--trace-signals", "state,fifo,gpp"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    save = os.path.join(tmp, "trace.gtkw")
    with open(save, "a") as f:  # a window that fills the virtual screen
        f.write(f"[size] {WIDTH} {HEIGHT}\n[pos] 0 0\n")
    shot, zoom = os.path.join(tmp, "shot.xwd"), os.path.join(tmp, "zoom.tcl")
    with open(zoom, "w") as f:
        f.write("gtkwave::/Time/Zoom/Zoom_Full\n")
    grab = f"gtkwave -S {zoom} {save} >/dev/null 2>&1 & sleep 10; xwd -root -silent -out {shot}; kill $!"
    subprocess.run(["xvfb-run", "-a", "-s", f"-screen 0 {WIDTH}x{HEIGHT}x24", "sh", "-c", grab], check=True)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    plt.imsave(a.out, read_xwd(shot))
    print(a.out)

