#!/usr/bin/python3
"""Tests of scripts/mutate (run by ctest, one entry per test class).

The tool is run on a throwaway git repository of two small files with two mutants, with trivial
build and test commands (`true`, `false`, a sleep), and interrupted with SIGINT, SIGTERM, both,
or killed outright; afterwards `git status --porcelain` must be empty and every file must hold
its original bytes. The real list (tests/mutants.txt) is checked to apply to this checkout.
"""
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MUTATE = os.path.join(REPO, "scripts", "mutate")

FILES = {
    "src/a.cpp": b"int twice(int x) { return x + x; }\nint limit = 4;\n",
    "src/b.h": b"inline bool below(int a, int b) { return a < b; }\n",
}
MUTANTS = """# two mutants, one per file
cover: src/ unit_tests

id: twice-minus
file: src/a.cpp
find: return x + x;
replace: return x - x;
rule: doubling

id: below-or-equal
file: src/b.h
find: a < b
replace: a <= b
rule: strict comparison
"""


class Repo:
    """A git repository in a temporary folder holding FILES and the mutant list."""

    def __init__(self, test, mutants=MUTANTS):
        self.tmp = tempfile.TemporaryDirectory(prefix="oprt_mutate_test_")
        test.addCleanup(self.tmp.cleanup)
        self.root = self.tmp.name
        for rel, data in FILES.items():
            self.write(rel, data)
        self.write("tests/mutants.txt", mutants.encode())
        for cmd in (["git", "init", "-q"], ["git", "add", "-A"],
                    ["git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "start"]):
            subprocess.run(cmd, cwd=self.root, check=True)

    def write(self, rel, data):
        path = os.path.join(self.root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)

    def read(self, rel):
        with open(os.path.join(self.root, rel), "rb") as f:
            return f.read()

    def start(self, *args):
        return subprocess.Popen([MUTATE, "--root", self.root] + list(args), stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)

    def run(self, *args, timeout=60):
        return subprocess.run([MUTATE, "--root", self.root] + list(args), capture_output=True, text=True,
                              timeout=timeout)

    def wait_for_mutant(self, rel, proc, timeout=30):
        """Waits until rel no longer holds its original bytes (a mutant is in place)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.read(rel) != FILES[rel]:
                return
            if proc.poll() is not None:
                raise AssertionError(f"mutate ended before {rel} was mutated: {proc.communicate()}")
            time.sleep(0.05)
        raise AssertionError(f"{rel} was never mutated")

    def assert_clean(self, test):
        status = subprocess.run(["git", "status", "--porcelain"], cwd=self.root, capture_output=True,
                                text=True, check=True).stdout
        test.assertEqual(status, "")
        for rel, data in FILES.items():
            test.assertEqual(self.read(rel), data, rel)
        gitdir = subprocess.run(["git", "rev-parse", "--absolute-git-dir"], cwd=self.root,
                                capture_output=True, text=True, check=True).stdout.strip()
        test.assertFalse(os.path.exists(os.path.join(gitdir, "oprt-mutate-journal")))


class TestOutcomes(unittest.TestCase):
    def test_a_failing_test_command_kills_both_mutants(self):
        repo = Repo(self)
        res = repo.run("--build-cmd", "true", "--test-cmd", "false")
        self.assertEqual(res.returncode, 0, res.stderr)
        self.assertIn("score: 2 of 2 killed (100.0 %)", res.stdout)
        self.assertEqual(res.stdout.count("killed     test command"), 4)  # two progress lines, two rows
        repo.assert_clean(self)

    def test_the_test_command_sees_the_mutant_and_the_score_counts_survivors(self):
        # The test fails only when a.cpp holds the mutant: one killed, one survived.
        repo = Repo(self)
        res = repo.run("--build-cmd", "true", "--test-cmd", "! grep -q 'x - x' src/a.cpp")
        self.assertEqual(res.returncode, 1, res.stdout + res.stderr)  # a survivor not marked equivalent
        self.assertRegex(res.stdout, r"twice-minus\s+killed")
        self.assertRegex(res.stdout, r"below-or-equal\s+survived")
        self.assertIn("score: 1 of 2 killed (50.0 %)", res.stdout)
        repo.assert_clean(self)

    def test_a_survivor_marked_equivalent_is_reported_with_its_reason(self):
        repo = Repo(self, MUTANTS.replace("rule: strict comparison", "rule: strict comparison\n"
                                    "equivalent: a and b never meet in this program"))
        res = repo.run("--build-cmd", "true", "--test-cmd", "! grep -q 'x - x' src/a.cpp")
        self.assertEqual(res.returncode, 0, res.stdout + res.stderr)
        self.assertRegex(res.stdout, r"below-or-equal\s+equivalent a and b never meet")
        self.assertIn("score: 1 of 2 killed (50.0 %); 1 equivalent, 0 survived", res.stdout)

    def test_a_build_that_fails_is_not_scored(self):
        repo = Repo(self)
        res = repo.run("--build-cmd", "echo 'a.cpp:1: error: nope'; false", "--test-cmd", "false")
        self.assertIn("score: no mutant built and ran (2 not built", res.stdout)
        self.assertIn("error: nope", res.stdout)
        repo.assert_clean(self)

    def test_only_selects_by_id_file_or_rule(self):
        repo = Repo(self)
        res = repo.run("--build-cmd", "true", "--test-cmd", "false", "--only", "strict")
        self.assertIn("score: 1 of 1 killed", res.stdout)
        self.assertNotIn("twice-minus", res.stdout)
        res = repo.run("--only", "nothing-like-this")
        self.assertEqual(res.returncode, 2)
        self.assertIn("--only: no mutant matches", res.stderr)


class TestInterruptions(unittest.TestCase):
    def interrupt(self, signals, rel="src/a.cpp", test_cmd="sleep 30"):
        repo = Repo(self)
        proc = repo.start("--build-cmd", "true", "--test-cmd", test_cmd)
        repo.wait_for_mutant(rel, proc)
        time.sleep(0.2)  # the test command is running
        for sig in signals:
            proc.send_signal(sig)
            time.sleep(0.05)
        out, err = proc.communicate(timeout=30)
        repo.assert_clean(self)
        return proc.returncode, out, err

    def test_sigint_while_the_first_mutant_is_tested(self):
        status, out, err = self.interrupt([signal.SIGINT])
        self.assertEqual(status, 128 + signal.SIGINT)
        self.assertIn("stopped by SIGINT; 0 of 2 mutants ran; the tree is restored", err)

    def test_sigterm_while_the_second_mutant_is_tested(self):
        # The first mutant is killed at once; the second one's test sleeps until SIGTERM.
        status, out, err = self.interrupt([signal.SIGTERM], rel="src/b.h",
                                          test_cmd="if grep -q 'x - x' src/a.cpp; then false; else sleep 30; fi")
        self.assertEqual(status, 128 + signal.SIGTERM)
        self.assertIn("1 of 2 mutants ran", err)
        self.assertRegex(out, r"twice-minus\s+killed")

    def test_sigint_then_sigterm_mid_run(self):
        status, out, err = self.interrupt([signal.SIGINT, signal.SIGTERM])
        self.assertEqual(status, 128 + signal.SIGINT)

    def test_a_killed_run_is_repaired_by_the_next_one(self):
        # SIGKILL cannot be caught: the mutant stays, and the journal under .git puts it back.
        repo = Repo(self)
        proc = repo.start("--build-cmd", "true", "--test-cmd", "sleep 3")  # orphaned: ends by itself
        repo.wait_for_mutant("src/a.cpp", proc)
        proc.kill()
        proc.communicate()
        self.assertNotEqual(repo.read("src/a.cpp"), FILES["src/a.cpp"])
        res = repo.run("--build-cmd", "true", "--test-cmd", "false", "--only", "below")
        self.assertIn("restoring it", res.stderr)
        repo.assert_clean(self)


class TestList(unittest.TestCase):
    def test_bad_lists_name_the_line(self):
        repo = Repo(self, MUTANTS.replace("replace: a <= b\n", ""))
        res = repo.run("--check")
        self.assertEqual(res.returncode, 2)
        self.assertIn("mutants.txt: mutant starting at line 10: missing `replace:`", res.stderr)
        repo = Repo(self, MUTANTS.replace("find: a < b", "find: a > b"))
        res = repo.run("--check")
        self.assertEqual(res.returncode, 1)
        self.assertIn("below-or-equal: src/b.h: the text to replace occurs 0 times", res.stderr)

    def test_the_projects_list_applies_to_this_checkout(self):
        # Every mutant's text occurs exactly once in its file (a list that no longer matches the
        # code fails here, e.g. after a file is split), every mutant has covering tests, and
        # the list covers the model's rules with at least 60 mutants.
        res = subprocess.run([MUTATE, "--check"], capture_output=True, text=True)
        self.assertEqual(res.returncode, 0, res.stderr)
        first = res.stdout.split(" mutants, ")
        total = int(first[0])
        self.assertGreaterEqual(total, 60)
        self.assertIn(f"{total} apply, {total} have covering tests", res.stdout)


if __name__ == "__main__":
    unittest.main()
