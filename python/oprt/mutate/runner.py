"""Applying a mutant, building and testing: children in their own process group (killed when
the run is interrupted), the file restored after every mutant, and a journal under the git
directory that repairs the tree after a run killed outright."""
import os
import re
import signal
import subprocess
import sys
import time

from .mutants import covering_regex, groups_for


class shielded:
    """Holds SIGINT and SIGTERM back while a file is restored or a child is stopped: a second
    signal must not leave a file half written. They are delivered when the block ends."""
    SIGNALS = {signal.SIGINT, signal.SIGTERM}

    def __enter__(self):
        self.old = signal.pthread_sigmask(signal.SIG_BLOCK, self.SIGNALS)

    def __exit__(self, *exc):
        signal.pthread_sigmask(signal.SIG_SETMASK, self.old)
        return False


class NoTests(Exception):
    """The covering tests' regular expression matches no test: the list is wrong, not the tests."""


class Runner:
    def __init__(self, args, root):
        self.args, self.root = args, root
        self.child = None
        self.journal = journal_path(root)

    def run(self, cmd, shell=False):
        """Runs cmd in its own process group; returns (exit status, output). The group is killed
        if we are interrupted."""
        self.child = subprocess.Popen(cmd, shell=shell, cwd=self.root, stdout=subprocess.PIPE,
                                      stderr=subprocess.STDOUT, start_new_session=True)
        try:
            out, _ = self.child.communicate()
        finally:
            with shielded():
                if self.child.poll() is None:
                    kill_group(self.child)
                status = self.child.returncode
                self.child = None
        return status, out.decode(errors="replace")

    # ---- build and test steps (overridable by --build-cmd / --test-cmd) ----
    def build(self, targets):
        if self.args.build_cmd is not None:
            return self.run(self.args.build_cmd, shell=True)
        cmd = ["cmake", "--build", self.args.build_dir, "-j", str(self.args.jobs)]
        if targets:
            cmd += ["--target"] + targets
        return self.run(cmd)

    def test(self, regex):
        """(killing test or None, exit status). regex None: the whole suite."""
        if self.args.test_cmd is not None:
            status, out = self.run(self.args.test_cmd, shell=True)
            return ("test command" if status != 0 else None), status
        cmd = ["ctest", "--test-dir", self.args.build_dir, "-j", str(self.args.jobs), "--no-tests=error",
               "--stop-on-failure", "--timeout", str(self.args.timeout)]
        if regex:
            cmd += ["-R", regex]
        else:  # the whole suite, but not the tool's own tests: its list check sees the mutant in place
            cmd += ["-E", "^mutate_tests:"]
        status, out = self.run(cmd)
        if status == 0:
            return None, 0
        failed = re.findall(r"Test\s+#\d+: (.*?) \.*\s*\*+(?:Failed|Exception|Timeout|Not Run)", out)
        if not failed:
            failed = re.findall(r"^\s*\d+ - (.*) \((?:Failed|Timeout|SEGFAULT|Subprocess aborted|Not Run)", out, re.M)
        if not failed and "No tests were found" in out:
            raise NoTests(regex or "")
        return (failed[0] if failed else f"ctest exit {status}"), status

    def targets_for(self, groups):
        """Build targets for ctest groups: a group named after a target builds it; the Python and
        golden tests need the oprt command."""
        known = self.known_targets()
        if groups and groups[0].startswith("^"):  # a regular expression: the targets it names
            groups = [t for t in sorted(known) if re.search(r"\b" + re.escape(t) + r"\b", groups[0])] or ["oprt"]
        out = []
        for g in groups:
            t = g if g in known else "oprt"
            if t not in out:
                out.append(t)
        return out

    def known_targets(self):
        if not hasattr(self, "_targets"):
            self._targets = set()
            try:
                res = subprocess.run(["ninja", "-C", self.args.build_dir, "-t", "targets", "all"],
                                     cwd=self.root, capture_output=True, text=True)
                for line in res.stdout.splitlines():
                    name = line.split(":")[0]
                    if "/" not in name and "." not in name:
                        self._targets.add(name)
            except OSError:
                pass
        return self._targets

    # ---- one mutant ----
    def mutate(self, mutant, original, mutated, cover):
        path = os.path.join(self.root, mutant["file"])
        write_journal(self.journal, mutant["file"], original)
        try:
            with open(path, "wb") as f:
                f.write(mutated)
            groups = groups_for(mutant, cover)
            regex = covering_regex(groups)
            if groups and self.args.build_cmd is None:
                status, out = self.build(self.targets_for(groups))
            else:
                status, out = self.build([])
            if status != 0:
                return "not built", first_error(out)
            if regex:
                try:
                    killer, _ = self.test(regex)
                except NoTests as e:
                    return "error", f"no test matches {e}"
                if killer:
                    return "killed", killer
            if self.args.narrow_only and regex:
                return "survived", "(covering tests only)"
            if regex and self.args.build_cmd is None:
                status, out = self.build([])
                if status != 0:
                    return "not built", first_error(out)
            killer, _ = self.test(None)
            if killer:
                return "killed", killer
            return "survived", ""
        finally:
            with shielded():
                restore(path, original)
                clear_journal(self.journal)


def first_error(out):
    for pattern in (": error:", "error"):
        for line in out.splitlines():
            if pattern in line:
                return line.strip()[:160]
    return out.strip().splitlines()[-1][:100] if out.strip() else ""


def kill_group(child):
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(child.pid, sig)
        except ProcessLookupError:
            return
        try:
            child.wait(timeout=5)
            return
        except subprocess.TimeoutExpired:
            continue


def restore(path, original):
    """Writes the original bytes back. The file gets a new modification time on purpose: the
    object files built from the mutant are newer than the original's old time, so a build
    would not recompile them, and the next mutant would be tested with this one still in it.
    Recompiling the original is a ccache hit."""
    with open(path, "r+b" if os.path.exists(path) else "wb") as f:
        f.write(original)
        f.truncate()
    now = time.time()
    os.utime(path, (now, now))


def journal_path(root):
    try:
        res = subprocess.run(["git", "rev-parse", "--absolute-git-dir"], cwd=root,
                             capture_output=True, text=True, check=True)
        return os.path.join(res.stdout.strip(), "oprt-mutate-journal")
    except (OSError, subprocess.CalledProcessError):
        return os.path.join(root, ".oprt-mutate-journal")


def write_journal(journal, rel, original):
    tmp = journal + ".tmp"
    with open(tmp, "wb") as f:
        f.write(rel.encode() + b"\0" + original)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, journal)


def clear_journal(journal):
    try:
        os.remove(journal)
    except FileNotFoundError:
        pass


def recover(journal, root):
    """A previous run was killed while a mutant was in place: put the original back."""
    try:
        with open(journal, "rb") as f:
            data = f.read()
    except FileNotFoundError:
        return
    rel, _, original = data.partition(b"\0")
    rel = rel.decode()
    print(f"mutate: a previous run was stopped with a mutant in {rel}; restoring it", file=sys.stderr)
    restore(os.path.join(root, rel), original)
    clear_journal(journal)

