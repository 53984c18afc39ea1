"""Evaluations in groups: one `oprt batch` process prices several configurations of a one-scene
space at the analytic level, loading the scene once and building each set of spheres and BVHs
once (testbench/batch_cmd.cpp). Each configuration keeps its folder trials/NNNNN/SCENE, with
the stats.json that `oprt render` writes, as a separate evaluation would."""
import json
import os
import subprocess
import time

from .. import render
from ..render import child_env
from .evaluate import Evaluation


class Group:
    """One `oprt batch` process and the configurations it prices, in order."""

    def __init__(self, run):
        self.run, self.members, self.proc, self.log = run, [], None, None
        self.t0 = None

    def start(self):
        run = self.run
        base = os.path.join(run.out, "trials", f"batch_{self.members[0].number:05d}")
        lines = [json.dumps({"args": run.oprt.batch_args(m.arch, m.config, m.resolution), "out": m.scene_dir(0)})
                 for m in self.members]
        with open(base + ".jsonl", "w") as f:
            f.write("\n".join(lines) + "\n")
        self.cmd = [run.oprt.binary, "batch", run.space.scene_files[0], "--archs", base + ".jsonl", "--out", base,
                    "--threads", str(run.threads)]
        self.log = open(base + ".log", "w+")
        self.t0 = time.time()
        self.proc = subprocess.Popen(self.cmd, stdout=self.log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                     env=child_env(), preexec_fn=render.die_with_parent())

    def running(self):
        return self.proc is not None and self.proc.poll() is None

    def ended(self):
        """The process's exit status once it has ended (None before)."""
        return None if self.proc is None else self.proc.poll()

    def last_words(self):
        self.log.flush()
        self.log.seek(0)
        return self.log.read()

    def stop(self):
        if self.proc is not None:
            render.stop(self.proc, 10)
        if self.log is not None and not self.log.closed:
            self.log.close()


class Member(Evaluation):
    """A configuration priced within a Group: judged once its status.json is written."""

    def __init__(self, run, number, config, group, resolution=None):
        self.group = group
        super().__init__(run, number, config, resolution=resolution)
        group.members.append(self)

    def start_next(self):  # the group's process renders it
        os.makedirs(self.scene_dir(0), exist_ok=True)
        self.cmd = None

    def status_file(self):
        return os.path.join(self.scene_dir(0), "status.json")

    def poll(self):
        if self.result is not None:
            return True
        g = self.group
        if g.proc is None:
            return False
        if os.path.exists(self.status_file()):
            with open(self.status_file()) as f:
                st = json.load(f)
            # Its time: from the previous configuration's end (or the process's start) to its own.
            i = g.members.index(self)
            before = os.path.getmtime(g.members[i - 1].status_file()) if i and os.path.exists(
                g.members[i - 1].status_file()) else g.t0
            self.wall = max(0.0, os.path.getmtime(self.status_file()) - before)
            return self.conclude(st["exit"], f"oprt: {st['message']}" if st.get("message") else "")
        rc = g.ended()
        if rc is not None:  # the process ended before this configuration
            self.result = {"outcome": "failed", "reason": f"oprt batch {'signal ' + str(-rc) if rc < 0 else 'exit status ' + str(rc)}"
                                                          f" before this configuration: {g.last_words()[-300:].strip()}"}
            return True
        if self.run.timeout and time.time() - g.t0 > self.run.timeout * len(g.members):
            g.stop()
            self.result = {"outcome": "failed", "reason": f"oprt batch ran longer than --timeout {self.run.timeout:g} s "
                                                          "per configuration"}
            return True
        return False

    def stop(self):
        self.group.stop()


class Groups:
    """The groups of a search: the one being filled, and those running."""

    def __init__(self, run, size):
        self.run, self.size = run, size
        self.forming = None
        self.all = []

    def usable(self):
        return self.size > 1 and len(self.run.space.scenes) == 1

    def add(self, number, config, resolution):
        if self.forming is None:
            self.forming = Group(self.run)
        return Member(self.run, number, config, self.forming, resolution=resolution)

    def start_ready(self, more_coming):
        """Starts the group being filled when it is full (or nothing more comes) and a core is free."""
        self.all = [g for g in self.all if g.running()]
        g = self.forming
        if g and g.members and (len(g.members) >= self.size or not more_coming) and len(self.all) < self.run.jobs:
            g.start()
            self.all.append(g)
            self.forming = None
