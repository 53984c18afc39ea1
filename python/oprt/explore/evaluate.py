"""Pricing one configuration: its oprt command lines, its runs one scene after the other, its figures and bounds."""
import copy
import json
import os
import re
import shutil
import subprocess
import time

from .. import render
from ..files import atomic_json
from ..render import child_env
from ..values import is_number
from .common import OBJECTIVES, PATH_PARAMS, UsageError


# -------------------------------------------------------------------- parameters -> oprt render
class Oprt:
    """The oprt binary and how a configuration becomes its command line. A parameter named like
    an `oprt render` option (its --help lists them) is passed as that option; any other name is
    an architecture-file key, dotted for nested objects (iu.triangle.adders). Nothing here knows
    the keys themselves: oprt judges them."""

    def __init__(self, binary, space):
        self.binary, self.space = binary, space
        try:
            r = subprocess.run([binary, "render", "--help"], capture_output=True, text=True, timeout=60)
        except OSError as e:
            raise UsageError(f"--oprt {binary}: cannot run: {e.strerror}")
        self.flags = set(re.findall(r"(?m)^\s+(?:-\w,)?--([a-z][a-z0-9-]*)", r.stdout))
        if "arch" not in self.flags:
            raise UsageError(f"--oprt {binary}: `render --help` lists no --arch option: not oprt?")
        self.foldable = set()  # options that the architecture file also takes, same name and meaning

    def is_flag(self, name):
        return "." not in name and name in self.flags

    def arch_doc(self, config, fold=False):
        """The architecture file of a configuration: the space's base, then every architecture
        parameter; with fold, also the options the architecture file takes as keys (the Pareto
        points' files, which `oprt render --arch` takes as they are)."""
        doc = copy.deepcopy(self.space.base_arch)
        for name, value in config.items():
            if self.is_flag(name):
                continue
            *path, key = name.split(".")
            node = doc
            for part in path:
                node = node.setdefault(part, {})
            node[key] = value
        if fold:  # an option whose key already holds an object (balance.locality) stays an option
            for name, value in config.items():
                if self.is_flag(name) and name in self.foldable and not isinstance(doc.get(name), dict):
                    doc[name] = value
        return doc

    def folded(self, name, config):
        """Whether the Pareto file holds option `name` (so the command leaves it out)."""
        return name in self.foldable and not isinstance(self.arch_doc({k: v for k, v in config.items()
                                                                       if not self.is_flag(k)}).get(name), dict)

    def flag_args(self, config, fold=False):
        args = []
        for name, value in config.items():
            if not self.is_flag(name) or (fold and self.folded(name, config)):
                continue
            if name in PATH_PARAMS:
                value = os.path.join(self.space.dir, value)
            text = "true" if value is True else "false" if value is False else \
                ",".join(map(str, value)) if isinstance(value, list) else str(value)
            args += [f"--{name}", text]
        return args

    def command(self, scene_file, arch_file, config, out, level, threads, frames=None, resolution=None, fold=False):
        cmd = [self.binary, "render", scene_file, "--arch", arch_file, "--level", level, "--out", out,
               "--no-progress", "--threads", str(threads)]
        return cmd + self.tail_args(config, frames, resolution, fold)

    def batch_args(self, arch_file, config, resolution=None):
        """A line of `oprt batch`: the options of one analytic render, without scene and outputs."""
        return ["--arch", arch_file, "--level", "analytic"] + self.tail_args(config, None, resolution, False)

    def tail_args(self, config, frames, resolution, fold):
        frames = frames if frames is not None else self.space.frames
        resolution = resolution if resolution is not None else self.space.resolution
        cmd = []
        if frames:
            cmd += ["--frames", frames]
        if resolution:
            cmd += ["--resolution", resolution]
        return cmd + self.flag_args(config, fold)


def oprt_message(log_text, arch_file=None):
    """oprt's own message (its last 'oprt: ...' line), without the generated file's path."""
    lines = [l.strip() for l in log_text.splitlines() if l.strip()]
    msg = next((l for l in reversed(lines) if l.startswith("oprt: ")), lines[-1] if lines else "no output")
    msg = msg[len("oprt: "):] if msg.startswith("oprt: ") else msg
    if arch_file:
        msg = msg.replace(arch_file + ": ", "").replace(arch_file, "the architecture file")
    return msg


def number_paths(node, prefix=""):
    """Dotted paths of the numbers in a JSON object (not inside lists)."""
    out = []
    for k, v in node.items():
        path = f"{prefix}{k}"
        if isinstance(v, dict):
            out += number_paths(v, path + ".")
        elif is_number(v):
            out.append(path)
    return out


# ----------------------------------------------------------------------------- one evaluation
def objectives_of(stats_list):
    """Objective figures of a configuration from its runs' stats.json (one per scene): frame
    time and energy per frame averaged over every rendered frame, area the largest run's."""
    frames = [fr for s in stats_list for fr in s.get("frames", [])]
    if not frames:
        raise KeyError("no frames")
    ft = [fr["frame_time_s"] for fr in frames]
    en = [fr["energy_j"]["total"] for fr in frames]
    area = max(s["area_mm2"]["total"] for s in stats_list)
    return {"frame_time_s": sum(ft) / len(ft), "energy_j": sum(en) / len(en), "area_mm2": area}


def frame_value(frame, key):
    node = frame
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node if is_number(node) else None


def judge(space, figures, stats_list):
    """(violations per constraint, readable broken bounds, constraint figures)."""
    violations, broken, values = [], [], {}
    frames = [fr for s in stats_list for fr in s.get("frames", [])]
    for key, bound, kind, _ in space.constraints:
        if key in OBJECTIVES:
            v = figures[key]
        else:
            vs = [frame_value(fr, key) for fr in frames]
            vs = [x for x in vs if x is not None]
            if not vs:
                values[key] = None
                violations.append(0.0)
                broken.append(f"{key} is not in stats.json")
                continue
            v = max(vs) if kind == "max" else min(vs)
        values[key] = v
        excess = (v - bound) if kind == "max" else (bound - v)
        violations.append(excess / max(abs(bound), 1e-300))
        if excess > 0:
            broken.append(f"{key} {v:.6g} {'>' if kind == 'max' else '<'} {bound:g} ({kind})")
    return violations, broken, values


class Evaluation:
    """One configuration priced by oprt: its scenes one after the other in the trial's folder."""

    def __init__(self, run, number, config, level="analytic", folder=None, arch_doc=None, fold=False, resolution=None):
        self.run, self.number, self.config, self.level = run, number, config, level
        self.resolution = resolution  # None: the space's
        self.dir = folder or os.path.join(run.out, "trials", f"{number:05d}")
        os.makedirs(self.dir, exist_ok=True)
        self.arch = os.path.join(self.dir, "arch.json") if arch_doc is None else arch_doc
        if arch_doc is None:
            atomic_json(self.arch, run.oprt.arch_doc(config))
        self.fold = fold
        self.scene_index, self.stats, self.wall, self.proc = 0, [], 0.0, None
        self.result = None
        self.start_next()

    def scene_dir(self, i):
        return os.path.join(self.dir, os.path.splitext(os.path.basename(self.run.space.scenes[i]))[0])

    def start_next(self):
        i = self.scene_index
        out = self.scene_dir(i)
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        self.cmd = self.run.oprt.command(self.run.space.scene_files[i], self.arch, self.config, out, self.level,
                                         self.run.threads, resolution=self.resolution, fold=self.fold)
        self.log = open(os.path.join(out, "log.txt"), "w+")
        self.t0 = time.time()
        self.proc = subprocess.Popen(self.cmd, stdout=self.log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                     env=child_env(), preexec_fn=render.die_with_parent())

    def poll(self):
        """True once the configuration is judged (self.result set)."""
        if self.result is not None:
            return True
        rc = self.proc.poll()
        if rc is None:
            if self.run.timeout and time.time() - self.t0 > self.run.timeout:
                self.proc.kill()
                self.proc.wait()
                self.wall += time.time() - self.t0
                self.log.close()
                self.result = {"outcome": "failed", "reason": f"oprt ran longer than --timeout {self.run.timeout:g} s"}
                return True
            return False
        self.wall += time.time() - self.t0
        self.log.seek(0)
        text = self.log.read()
        self.log.close()
        return self.conclude(rc, text)

    def conclude(self, rc, text):
        """A scene's run ended with status rc and log text: the next scene, or the result.
        True once the configuration is judged."""
        out = self.scene_dir(self.scene_index)
        if rc == 0:
            try:
                with open(os.path.join(out, "stats.json")) as f:
                    self.stats.append(json.load(f))
            except (OSError, ValueError) as e:
                self.result = {"outcome": "failed", "reason": f"no readable stats.json ({e})"}
                return True
            for name in os.listdir(out):  # the image is the scene's, the same for every configuration
                if re.fullmatch(r"frame_\d+\.(exr|png)", name):
                    os.unlink(os.path.join(out, name))
            self.scene_index += 1
            if self.scene_index < len(self.run.space.scenes):
                self.start_next()
                return False
            try:
                figures = objectives_of(self.stats)
            except (KeyError, TypeError, ValueError) as e:
                self.result = {"outcome": "failed", "reason": f"stats.json without frame time, energy or area ({e})"}
                return True
            violations, broken, values = judge(self.run.space, figures, self.stats)
            self.result = {"outcome": "infeasible" if broken else "complete", "reason": "; ".join(broken),
                           "figures": figures, "violations": violations, "constraint_values": values}
            return True
        msg = oprt_message(text, self.arch)
        scene = self.run.space.scenes[self.scene_index]
        where = f" ({scene})" if len(self.run.space.scenes) > 1 else ""
        if rc == 2:
            self.result = {"outcome": "infeasible", "reason": f"refused by oprt{where}: {msg}"}
        else:
            how = f"signal {-rc}" if rc < 0 else f"exit status {rc}"
            self.result = {"outcome": "failed", "reason": f"oprt {how}{where}: {msg}"}
        return True

    def stop(self):
        if self.proc:
            render.stop(self.proc, 10)
        if not self.log.closed:
            self.log.close()


class Reused:
    """A configuration whose outcome is taken from another explore output (--reuse)."""

    def __init__(self, record):
        self.result = {k: v for k, v in record.items() if v is not None}
        self.wall = record.get("wall_s", 0.0)

    def poll(self):
        return True

    def stop(self):
        pass
