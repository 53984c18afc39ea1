"""matplotlib for files (no display), installed on first use, and the styles plots share."""
import os
import subprocess
import sys
import tempfile

from . import paths

#: A unit model's colour in every plot of sweeps and searches.
MODEL_COLOURS = {"serial": "#4878d0", "pipelined": "#ee854a"}


def require(setup_target, *modules):
    """Imports `modules` (default matplotlib); where one is missing (first use on this machine),
    runs scripts/setup SETUP_TARGET and starts this script again."""
    import importlib
    try:
        for m in modules or ("matplotlib",):
            importlib.import_module(m)
    except ImportError:
        subprocess.run([os.path.join(paths.REPO, "scripts", "setup"), setup_target], check=True)
        os.execv(sys.executable, [sys.executable] + sys.argv)


def pyplot(setup_target="plots"):
    """matplotlib.pyplot with the file-only backend (Agg), installed first if need be."""
    require(setup_target)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def log_if_wide(ax, xs, ys, ratio=4, minor=False):
    """A log scale on each axis whose positive values span more than `ratio`, its ticks as plain
    numbers (with minor, the 2s and 5s between the decades labelled too)."""
    import matplotlib.ticker
    plain = matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}")
    for values, set_scale, axis in ((xs, ax.set_xscale, ax.xaxis), (ys, ax.set_yscale, ax.yaxis)):
        if values and min(values) > 0 and max(values) > ratio * min(values):
            set_scale("log")
            axis.set_major_formatter(plain)
            if minor:
                axis.set_minor_formatter(matplotlib.ticker.FuncFormatter(
                    lambda v, _: f"{v:g}" if f"{v:g}"[0] in "25" else ""))


def atomic_savefig(fig, path, dpi=110):
    """Saves a figure as PNG under a temporary name, then renames it to `path`."""
    d, base = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=f".{base}.", suffix=".png")
    os.close(fd)
    try:
        fig.savefig(tmp, format="png", dpi=dpi)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
