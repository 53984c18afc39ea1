"""The mutant list (tests/mutants.txt): its `cover:` lines and mutant blocks read and checked,
the tests that cover a mutant, and whether a mutant applies (its text once in its file)."""
import os
import re
import sys

FIELDS = ("id", "file", "find", "replace", "rule", "tests", "equivalent")


def fail(message):
    print(f"mutate: {message}", file=sys.stderr)
    sys.exit(2)


def unescape(text):
    """`\\n` and `\\t` in find/replace stand for a newline and a tab; `\\\\` for a backslash."""
    return re.sub(r"\\(.)", lambda m: {"n": "\n", "t": "\t", "\\": "\\"}.get(m.group(1), m.group(0)), text)


def parse_list(path):
    """Returns (cover, mutants). `cover: PREFIX TEST...` lines map path prefixes to the ctest groups
    (the part of a ctest name before ": ") that cover them; the mutants are blocks of
    `key: value` lines separated by blank lines; `#` starts a comment line."""
    try:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    cover, mutants, block, start = [], [], {}, 0

    def close(lineno):
        nonlocal block
        if not block:
            return
        if "cover" in block:
            fail(f"{path}: line {lineno}: `cover:` lines stand alone, not in a mutant's block")
        for key in ("id", "file", "find", "replace", "rule"):
            if key not in block:
                fail(f"{path}: mutant starting at line {start}: missing `{key}:`")
        block["line"] = start
        mutants.append(block)
        block = {}

    for n, line in enumerate(lines, 1):
        if line.startswith("#"):
            continue
        if not line.strip():
            close(n)
            continue
        key, sep, value = line.partition(":")
        key = key.strip()
        if not sep:
            fail(f"{path}: line {n}: expected `key: value`")
        value = value[1:] if value.startswith(" ") else value
        if key == "cover" and not block:
            parts = value.split()
            if len(parts) < 2:
                fail(f"{path}: line {n}: `cover: PATH-PREFIX TEST-GROUP...`")
            cover.append((parts[0], parts[1:]))
            continue
        if key not in FIELDS:
            fail(f"{path}: line {n}: unknown key {key!r} (expected one of: {', '.join(FIELDS)})")
        if key in block:
            fail(f"{path}: line {n}: `{key}:` given twice in one mutant")
        if not block:
            start = n
        block[key] = unescape(value) if key in ("find", "replace") else value.strip()
    close(len(lines))
    ids = [m["id"] for m in mutants]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        fail(f"{path}: mutant ids given twice: {', '.join(dup)}")
    return cover, mutants


def groups_for(mutant, cover):
    """The ctest groups that cover the mutant: a list of names, or [regex] when `tests:` is a
    ctest regular expression (it starts with ^)."""
    if mutant.get("tests"):
        return [mutant["tests"]] if mutant["tests"].startswith("^") else mutant["tests"].split()
    best = None
    for prefix, groups in cover:
        if mutant["file"].startswith(prefix) and (best is None or len(prefix) > len(best[0])):
            best = (prefix, groups)
    return best[1] if best else []


def check_mutant(mutant, root):
    """The original bytes and the mutated bytes, or an error message."""
    path = os.path.join(root, mutant["file"])
    try:
        with open(path, "rb") as f:
            original = f.read()
    except OSError as e:
        return None, None, f"{mutant['file']}: {e.strerror}"
    find = mutant["find"].encode()
    count = original.count(find)
    if count != 1:
        return None, None, f"{mutant['file']}: the text to replace occurs {count} times (must be once): {mutant['find']!r}"
    if mutant["find"] == mutant["replace"]:
        return None, None, "replacement equals the original"
    return original, original.replace(find, mutant["replace"].encode()), None


def covering_regex(groups):
    if not groups:
        return None
    if groups[0].startswith("^"):
        return groups[0]
    return "^(" + "|".join(re.escape(g) for g in groups) + "):"  # catch_discover_tests drops the space

