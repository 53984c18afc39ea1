"""Files written whole or not at all: under a hidden temporary name of their own in the same
folder, flushed to disk, then renamed into place (a killed process never leaves half a file)."""
import csv
import io
import json
import os
import tempfile


def write_atomically(path, write, mode="w"):
    """Calls write(f) on a temporary file beside `path` (opened with `mode`), then renames it
    to `path`; the temporary file is removed if anything fails."""
    d, base = os.path.split(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=f".{base}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode, newline="" if "b" not in mode else None) as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write(path, data):
    """Writes text or bytes to `path` atomically."""
    write_atomically(path, lambda f: f.write(data.encode() if isinstance(data, str) else data), "wb")


def atomic_json(path, doc):
    """Writes `doc` as indented JSON (and a newline) to `path` atomically."""
    write_atomically(path, lambda f: (json.dump(doc, f, indent=1), f.write("\n")))


def csv_text(fields, rows):
    """CSV text of `rows` (dicts) under the header `fields`, with '\\n' line ends."""
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    return buf.getvalue()
