"""Where things are: the repository this package lives in, its scenes, the oprt binary.

The package runs from a checkout (python/oprt, found by the scripts' bootstrap) or installed:
by pip into an environment (ENV/lib/python3.X/site-packages/oprt) or by `cmake --install`
under a prefix (PREFIX/lib/python3/dist-packages/oprt, beside PREFIX/bin/oprt).
"""
import os
import shutil

_HERE = os.path.dirname(os.path.abspath(__file__))
#: The repository's root (python/oprt/paths.py -> the folder above python/).
REPO = os.path.dirname(os.path.dirname(_HERE))
#: Whether the package is a checkout's python/oprt rather than an installed copy.
IN_CHECKOUT = os.path.basename(os.path.dirname(_HERE)) == "python" and os.path.isdir(os.path.join(REPO, "testbench"))
#: Read-only material beside the repository (BART scenes in SHARED/bart).
SHARED = os.path.join(os.path.dirname(REPO), "shared")
SCENES = os.path.join(REPO, "scenes")
TECH = os.path.join(REPO, "testbench", "tech")
ARCH = os.path.join(REPO, "testbench", "arch")
#: The checkout's build of the oprt command.
BUILD_OPRT = os.path.join(REPO, "build", "testbench", "oprt")


def installed_oprt():
    """The oprt command of the prefix an installed package lies under (PREFIX/bin/oprt, up to
    four folders above the package: lib/python3/dist-packages/oprt), else `oprt` on PATH, else None."""
    folder = _HERE
    for _ in range(4):
        folder = os.path.dirname(folder)
        candidate = os.path.join(folder, "bin", "oprt")
        if os.path.isfile(candidate) and os.access(candidate, os.X_OK):
            return candidate
    return shutil.which("oprt")


def oprt_binary(explicit=None):
    """The oprt binary to run: `explicit` if given, else $OPRT_BINARY, else the checkout's build
    (build/testbench/oprt); an installed package: the installed command (`installed_oprt`)."""
    found = explicit or os.environ.get("OPRT_BINARY")
    if found:
        return found
    if IN_CHECKOUT:
        return BUILD_OPRT
    return installed_oprt() or "oprt"
