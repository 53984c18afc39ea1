"""Checking a space with oprt (one pixel per value) and the output folder before a search starts."""
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time

from .. import render
from ..values import show
from .common import OBJECTIVES, PATH_PARAMS, SpaceError, UsageError, config_key
from ..render import child_env
from .evaluate import number_paths, oprt_message


# ----------------------------------------------------------------- checking a space with oprt
def probe_space(space, oprt, jobs, file):
    """Renders one pixel of the first scene per parameter value (the others at their first
    value), so that a name or value oprt does not take is an error before any evaluation.
    A value that oprt refuses only beside the others' first values (a combination the model does
    not support) is not an error: such configurations are recorded as infeasible. Returns the
    per-frame stats keys seen (for the constraints). Raises SpaceError."""
    tmp = tempfile.mkdtemp(prefix="oprt-explore-probe-")
    results = {}

    def run_all(configs):
        todo = [c for c in configs if config_key(c) not in results]
        seen, queue, running = set(), [], []
        for c in todo:
            if config_key(c) not in seen:
                seen.add(config_key(c))
                queue.append(c)
        while queue or running:
            while queue and len(running) < jobs:
                c = queue.pop(0)
                d = tempfile.mkdtemp(dir=tmp)
                arch = os.path.join(d, "probe-arch.json")
                with open(arch, "w") as f:
                    json.dump(oprt.arch_doc(c), f)
                cmd = oprt.command(space.scene_files[0], arch, c, d, "analytic", 1, frames=space.first_frame,
                                   resolution="1x1")
                log = open(os.path.join(d, "log.txt"), "w+")
                running.append((c, d, arch, log, subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT,
                                                                  stdin=subprocess.DEVNULL, env=child_env(),
                                                                  preexec_fn=render.die_with_parent())))
            for item in list(running):
                c, d, arch, log, proc = item
                if proc.poll() is None:
                    continue
                running.remove(item)
                log.seek(0)
                text = log.read()
                log.close()
                keys = set()
                if proc.returncode == 0:
                    try:
                        with open(os.path.join(d, "stats.json")) as f:
                            stats = json.load(f)
                        for fr in stats.get("frames", []):
                            keys |= set(number_paths(fr))
                    except (OSError, ValueError):
                        pass
                results[config_key(c)] = (proc.returncode, oprt_message(text, arch), keys)
            time.sleep(0.01)

    try:
        fixed = {p.name: p.value for p in space.params if not p.varied}
        firsts = {p.name: p.first() for p in space.params}
        wanted = [firsts]
        for p in space.params:
            wanted += [{**firsts, p.name: v} for v in p.probe_values()]
        for name, ref in space.references:
            wanted.append(ref)
        run_all(wanted)
        # A value refused beside the others' first values: refused on its own as well?
        alone = []
        for p in space.params:
            for v in p.probe_values():
                rc, _, _ = results[config_key({**firsts, p.name: v})]
                if rc == 2:
                    alone.append({p.name: v})
        run_all(alone)
        for p in space.params:
            for i, v in enumerate(p.probe_values()):
                rc, msg, _ = results[config_key({**firsts, p.name: v})]
                if rc != 2:
                    continue
                rc_alone, msg_alone, _ = results[config_key({p.name: v})]
                if rc_alone == 2 and msg_alone == msg:
                    where = p.where + (f"/choice/{p.values.index(v)}" if p.kind == "choice" else
                                       f"/{p.kind}" if p.kind != "fixed" else "")
                    if "unknown key" in msg or "not expected" in msg:
                        raise SpaceError(file, p.where, f"unknown parameter {p.name}: neither an oprt render option "
                                                        f"nor an architecture-file key (oprt: {msg})")
                    raise SpaceError(file, where, f"{p.name} = {show(v)}: oprt refuses it: {msg}")
        for name, ref in space.references:
            rc, msg, _ = results[config_key(ref)]
            if rc == 2:
                raise SpaceError(file, f"/references/{name}", f"oprt refuses it: {msg}")
        # Options the architecture file also takes (ius, balance, accel, ...): folded into the
        # Pareto points' architecture files.
        folds = []
        for p in space.params:
            if oprt.is_flag(p.name) and p.name not in PATH_PARAMS:
                doc = {"format": "oprt-arch/1", p.name: p.first()}
                folds.append((p.name, doc))
        for name, doc in folds:
            d = tempfile.mkdtemp(dir=tmp)
            arch = os.path.join(d, "fold.json")
            with open(arch, "w") as f:
                json.dump(doc, f)
            r = subprocess.run([oprt.binary, "render", space.scene_files[0], "--arch", arch, "--level", "analytic",
                                "--frames", space.first_frame, "--resolution", "1x1", "--out", d, "--no-progress",
                                "--threads", "1"], capture_output=True, text=True, env=child_env(),
                               preexec_fn=render.die_with_parent())
            if r.returncode == 0:
                oprt.foldable.add(name)
        keys = set()
        for rc, _, k in results.values():
            keys |= k
        base_rc, base_msg, _ = results[config_key(firsts)]
        if base_rc not in (0, 2):
            print(f"explore: note: oprt failed (exit status {base_rc}) on the first values: {base_msg}", file=sys.stderr)
        return keys
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def check_constraint_keys(space, keys, file):
    for key, _, _, where in space.constraints:
        if key in OBJECTIVES or key in keys:
            continue
        known = ", ".join(sorted(k for k in keys if k.count(".") <= 1))
        raise SpaceError(file, where.rsplit("/", 1)[0], f"unknown key {key}: neither an objective ({', '.join(OBJECTIVES)}) "
                                                        f"nor a per-frame number of stats.json (known: {known})")


# ----------------------------------------------------------------------------- output folder
def check_out_dir(path, option="--out"):
    """An output folder must be a writable directory, or creatable; raises UsageError naming
    the option otherwise. An existing non-empty folder must be an explore output."""
    if os.path.lexists(path):
        try:
            st = os.stat(path)
        except OSError as e:
            raise UsageError(f"{option} {path}: {e.strerror}")
        if not stat.S_ISDIR(st.st_mode):
            kind = ("a regular file" if stat.S_ISREG(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode) else
                    "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else
                    "a socket" if stat.S_ISSOCK(st.st_mode) else "not a directory")
            raise UsageError(f"{option} {path}: is {kind}, not a directory")
        if not writable(path):
            raise UsageError(f"{option} {path}: the directory is not writable")
        if os.listdir(path) and not os.path.isfile(os.path.join(path, "explore.json")):
            raise UsageError(f"{option} {path}: a directory that holds other files and no explore.json: "
                             "not an explore output; give a new or empty folder")
        return
    parent = os.path.dirname(os.path.abspath(path))
    while not os.path.lexists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        raise UsageError(f"{option} {path}: cannot be created: {parent} is not a directory")
    if not writable(parent):
        raise UsageError(f"{option} {path}: cannot be created: {parent} is not writable")


def writable(folder):
    """Whether a directory can be created in `folder` (tried, then removed: permissions alone
    do not tell, e.g. for root on a read-only or virtual file system)."""
    try:
        os.rmdir(tempfile.mkdtemp(dir=folder, prefix=".explore-check-"))
        return True
    except OSError:
        return False
