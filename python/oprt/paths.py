"""Where things are: the repository this package lives in, its scenes, the oprt binary."""
import os

#: The repository's root (python/oprt/paths.py -> the folder above python/).
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
#: Read-only material beside the repository (BART scenes in SHARED/bart).
SHARED = os.path.join(os.path.dirname(REPO), "shared")
SCENES = os.path.join(REPO, "scenes")
TECH = os.path.join(REPO, "testbench", "tech")
ARCH = os.path.join(REPO, "testbench", "arch")


def oprt_binary(explicit=None):
    """The oprt binary to run: `explicit` if given, else $OPRT_BINARY, else the build's."""
    return explicit or os.environ.get("OPRT_BINARY") or os.path.join(REPO, "build", "testbench", "oprt")
