"""The one bootstrap of the scripts: puts this checkout's python/ first on sys.path, so that
`import oprt` finds the package beside the scripts (an installed oprt is not needed, and a
checkout's scripts never run another checkout's package)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(__file__))), "python"))
