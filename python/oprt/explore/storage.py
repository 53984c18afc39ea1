"""The study's store: Optuna, SQLite / journal / database storages, and another output's evaluations (--reuse)."""
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings

from .. import paths
from .common import UsageError, reuse_key
from .space import load_space


# ---------------------------------------------------------------------------------- the study
def import_optuna():
    try:
        import optuna
    except ImportError:  # first use on this machine: install it (scripts/setup explore), then start again
        setup = os.path.join(paths.REPO, "scripts", "setup")
        if os.environ.get("OPRT_EXPLORE_SETUP_TRIED") or subprocess.run([setup, "explore"]).returncode != 0:
            raise UsageError("needs Optuna: apt-get install python3-optuna (scripts/setup explore), and Debian's "
                             "/usr/bin/python3 to run it")
        os.environ["OPRT_EXPLORE_SETUP_TRIED"] = "1"
        os.execv(sys.executable, [sys.executable] + sys.argv)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    warnings.filterwarnings("ignore", category=optuna.exceptions.ExperimentalWarning)
    return optuna


def open_storage(optuna, spec, out, create):
    """The study store: the default SQLite file in DIR, a database URL, or a journal file."""
    if spec is None:
        path = os.path.join(out, "study.db")
        if not os.path.exists(path) and create:
            # Created under a temporary name, then renamed: a kill during creation leaves no
            # half-made database behind.
            fd, tmp = tempfile.mkstemp(dir=out, prefix=".study.", suffix=".db")
            os.close(fd)
            os.unlink(tmp)
            s = optuna.storages.RDBStorage(f"sqlite:///{tmp}", engine_kwargs={"connect_args": {"timeout": 120}})
            s.remove_session()  # the tables exist now
            s.engine.dispose()
            os.replace(tmp, path)
        return sqlite_storage(optuna, path)
    if "://" in spec:
        kwargs = {"connect_args": {"timeout": 120}} if spec.startswith("sqlite") else {}
        return optuna.storages.RDBStorage(spec, engine_kwargs=kwargs)
    path = spec[len("journal:"):] if spec.startswith("journal:") else spec
    repair_journal(path)
    return optuna.storages.JournalStorage(optuna.storages.JournalFileStorage(path))


def sqlite_storage(optuna, path):
    """The default study: SQLite in write-ahead-log mode, without an fsync per commit (a trial
    costs some twenty commits; at 13 ms each they were most of a search's time). A process
    killed at any moment (SIGKILL included) loses nothing committed and leaves the database
    consistent; only a power cut may lose the last evaluations (never corrupt the study)."""
    import sqlalchemy

    # One connection kept open (SQLAlchemy 1.4 opens one per session for a SQLite file by
    # default, and closing the last one checkpoints the log with an fsync).
    storage = optuna.storages.RDBStorage(f"sqlite:///{path}", engine_kwargs={
        "connect_args": {"timeout": 120}, "poolclass": sqlalchemy.pool.SingletonThreadPool})

    def pragmas(connection, _record):
        cursor = connection.cursor()
        cursor.execute("PRAGMA journal_mode=WAL")
        cursor.execute("PRAGMA synchronous=NORMAL")
        cursor.close()

    sqlalchemy.event.listen(storage.engine, "connect", pragmas)
    storage.engine.dispose()  # connections made before the listener: closed, so every one has the pragmas
    return storage


def repair_journal(path):
    """A journal file left by a process killed while appending: a stale lock link (older than
    a minute; appends take milliseconds) is removed, and a last line without its newline is cut."""
    lock = path + ".lock"
    try:
        if os.path.islink(lock) and time.time() - os.lstat(lock).st_mtime > 60:
            os.unlink(lock)
            print(f"explore: removed the stale journal lock {lock}", file=sys.stderr)
    except OSError:
        pass
    if not os.path.isfile(path) or os.path.lexists(lock):
        return
    with open(path, "rb+") as f:
        data = f.read()
        if data and not data.endswith(b"\n"):
            cut = data.rfind(b"\n") + 1
            f.truncate(cut)
            print(f"explore: cut a half-written last entry from {path}", file=sys.stderr)


def load_reused(optuna, folder, space):
    manifest = os.path.join(folder, "explore.json")
    if not os.path.isfile(manifest):
        raise UsageError(f"--reuse {folder}: not an explore output (no explore.json)")
    with open(manifest) as f:
        m = json.load(f)
    if m.get("eval_hash") != space.eval_hash:
        raise UsageError(f"--reuse {folder}: its evaluations are of other scenes, frames, resolution, base "
                         "architecture or bounds")
    other = load_space(m["space"])
    storage = open_storage(optuna, m.get("storage"), os.path.abspath(folder), create=False)
    study = optuna.load_study(study_name="explore", storage=storage)
    table = {}
    for t in study.get_trials(deepcopy=False):
        e = t.user_attrs.get("evaluation") if t.state.name == "COMPLETE" else None
        if e:
            # Keyed by configuration and resolution: "@" is the space's (the target fidelity).
            screened = t.user_attrs.get("fidelity") == "screen"
            table[reuse_key(other, e["config"]) + "@" + (e.get("resolution", "") if screened else "")] = {"outcome": e["outcome"], "reason": e["reason"], "figures": e["figures"],
                                             "violations": e["violations"],
                                             "constraint_values": e["constraint_values"], "wall_s": e["wall_s"],
                                             "config": e["config"]}
    return table
