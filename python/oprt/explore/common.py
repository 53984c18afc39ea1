"""The names a space and a search share: objectives, reserved options, errors, configurations."""
import itertools
import json
import os


FORMAT = "oprt-space/1"
RUN_FORMAT = "oprt-explore/1"

OBJECTIVES = ("frame_time_s", "energy_j", "area_mm2")
UNITS = {"frame_time_s": (1e3, "ms"), "energy_j": (1e3, "mJ"), "area_mm2": (1, "mm2")}
AXIS_LABELS = {"frame_time_s": "frame time (ms)", "energy_j": "energy per frame (mJ)", "area_mm2": "area (mm2)"}
# `oprt render` options explore sets itself: not parameters.
RESERVED = {
    "arch": "explore writes each configuration's architecture file",
    "out": "explore chooses each run's output folder",
    "level": "evaluations run --level analytic, the Pareto points --level at",
    "frames": 'give the frames as the space\'s "frames"',
    "resolution": 'give the resolution as the space\'s "resolution"',
    "threads": "explore shares the cores between its --jobs",
    "no-progress": "explore runs oprt without its progress bar",
    "vcd": "a search traces nothing", "timeline": "a search traces nothing",
    "trace-frames": "a search traces nothing", "trace-window": "a search traces nothing",
    "trace-units": "a search traces nothing", "trace-signals": "a search traces nothing",
    "trace-buffer": "a search traces nothing", "help": "not a parameter", "format": "not a parameter",
    "comment": "not a parameter", "source": "not a parameter",
}
PATH_PARAMS = ("tech",)  # values are files, relative to the space file
SPACE_KEYS = ("format", "comment", "scenes", "frames", "resolution", "arch", "parameters", "objectives",
              "constraints", "references", "reference_point", "population", "start")
FAILED_PENALTY = 1e6  # the refusal entry of the constraint vector: worse than any broken bound
HEARTBEAT_S = 20


class SpaceError(Exception):
    """A bad space file: str() is 'FILE: /json/path: problem'."""

    def __init__(self, file, path, problem):
        super().__init__(f"{file}: {path or '/'}: {problem}")


class UsageError(Exception):
    """A bad command line or output folder (exit status 2)."""


def finite_size(space):
    n = 1
    for p in space.params:
        k = p.size()
        if k is None:
            return None
        n *= k
    return n


def grid_points(space, file):
    ranges = [p for p in space.params if p.kind in ("int", "float")]
    if ranges:
        raise SpaceError(file, ranges[0].where, f"--grid needs every parameter to be a choice or fixed: "
                                                f"{ranges[0].name} is a range (write it as {{\"choice\": [...]}})")
    varied = [p for p in space.params if p.varied]
    return [dict(zip([p.name for p in varied], values)) for values in itertools.product(*(p.values for p in varied))]


def full_config(space, varied_values):
    """Every parameter's value, in the space's order (fixed ones included)."""
    return {p.name: (varied_values[p.name] if p.varied else p.value) for p in space.params}


def config_key(config):
    return json.dumps(config, sort_keys=True)


def reuse_key(space, config):
    """A configuration as another space file names it: file parameters as absolute paths."""
    return config_key({k: os.path.normpath(os.path.join(space.dir, v)) if k in PATH_PARAMS and isinstance(v, str) else v
                       for k, v in config.items()})
