"""A search in an output folder: the study, its evaluations and the loop that asks, evaluates and tells."""
import json
import math
import os
import sys
import time

from ..files import atomic_write, csv_text
from ..pareto import hypervolume
from ..values import fmt_time, show
from .common import OBJECTIVES, UNITS, FAILED_PENALTY, UsageError, full_config, config_key
from .fidelity import TARGET, UNBOUNDED, Clock, dominates
from .storage import open_storage


class Run:
    """A search in an output folder: the study, its evaluations, its outputs."""

    def __init__(self, args, space, oprt, optuna):
        self.args, self.space, self.oprt, self.optuna = args, space, oprt, optuna
        self.out = os.path.abspath(args.out)
        self.jobs = args.jobs
        self.threads = max(1, len(os.sched_getaffinity(0)) // max(1, self.jobs))
        self.timeout = args.timeout
        self.stop_signal = None
        self.varied = [p for p in space.params if p.varied]
        self.reused = {}
        self.ledger = {}  # trial number -> the FrozenTrial of each evaluation
        self.clock = Clock(None)
        self.mirror = None  # a local study in memory, written through to its file (mirror.py)
        self.screen = None  # the screening resolution, or None (every evaluation at the target fidelity)
        self.rung = 10  # screened evaluations between promotions
        self.promoted = set()  # config keys queued at the target fidelity by this process
        self.front_size = 0
        self.last_write = 0.0
        self.front = []  # the feasible target-fidelity evaluations no other dominates, kept as they come

    # ---- the study
    def sampler(self, seed):
        optuna = self.optuna
        if self.args.grid:
            return optuna.samplers.RandomSampler(seed=seed)
        n_constraints = len(self.space.constraints) + 1

        def constraints(trial):
            return trial.user_attrs.get("evaluation", {}).get("violations_all", [0.0] * n_constraints)

        if self.args.sampler == "portfolio":
            from .samplers import portfolio_sampler
            return portfolio_sampler(optuna, seed, self.population(), constraints)
        if self.args.sampler == "tpe":
            return optuna.samplers.TPESampler(seed=seed, constraints_func=constraints, multivariate=True,
                                              n_startup_trials=self.startup_trials())
        return optuna.samplers.NSGAIISampler(seed=seed, constraints_func=constraints,
                                             population_size=self.population())

    def population(self):
        """NSGA-II's generation: the space's "population", else a tenth of the evaluations
        between 10 and 50 (Optuna's default), so that even a short search has generations."""
        if self.space.population:
            return self.space.population
        return max(10, min(50, self.args.evaluations // 10))

    def startup_trials(self):
        return max(10, min(50, self.args.evaluations // 10))

    def open_study(self, create):
        self.storage = open_storage(self.optuna, self.args.storage, self.out, create)
        seed = self.args.seed
        try:
            existing = self.optuna.load_study(study_name="explore", storage=self.storage).trials
        except KeyError:
            existing = []
        if existing:
            # A resumed search: a seed derived from the seed and how far the study got, so that
            # the sampler neither replays the proposals already made nor depends on the clock.
            seed = seed + 7919 * len(existing)
        task = os.environ.get("SLURM_ARRAY_TASK_ID")
        if self.args.worker and task:  # each task its own random stream, all in one study
            seed = seed + 1000003 * (int(task) + 1)
        self.seed_used = seed
        self.study = self.optuna.create_study(storage=self.storage, study_name="explore", load_if_exists=True,
                                              directions=["minimize"] * len(self.space.objectives),
                                              sampler=self.sampler(seed))
        if len(self.study.directions) != len(self.space.objectives):
            raise UsageError(f"--out {self.args.out}: its study has {len(self.study.directions)} objectives, "
                             f"the space {len(self.space.objectives)}")

    def go_in_memory(self):
        """A local study from here on: in memory, written through to its file (mirror.py)."""
        from .mirror import Mirror
        memory = self.optuna.create_study(directions=["minimize"] * len(self.space.objectives),
                                          sampler=self.sampler(self.seed_used))
        self.mirror = Mirror(self.optuna, self.storage, memory)
        self.study, self.storage = memory, memory._storage

    def persist(self, number):
        if self.mirror is not None:
            self.mirror.write(number)

    def flush(self):
        if self.mirror is not None:
            self.mirror.flush()

    def trials(self):
        return self.study.get_trials(deepcopy=False)

    @staticmethod
    def evaluation(t):
        """The evaluation a trial holds, or None (duplicates, surplus, interrupted, running)."""
        if t.state.name == "COMPLETE" or (t.state.name == "PRUNED" and t.user_attrs.get("fidelity") == TARGET):
            return t.user_attrs.get("evaluation")
        return None

    def final(self, trials):
        """The evaluations at the target fidelity (all of them when the search does not screen)."""
        return [t for t in trials if t.user_attrs.get("fidelity", TARGET) == TARGET]

    def done(self):
        """Every evaluation the study holds, in trial order (the study read again)."""
        self.refresh()
        return [self.ledger[n] for n in sorted(self.ledger)]

    def recover(self, shared):
        """Trials left running by a process that is gone: failed (they count for nothing) and
        their configurations queued again. Locally every running trial is such a trial (the
        folder's lock is ours); with a shared study, those without a heartbeat for --stale-after."""
        now = time.time()
        for t in self.study.get_trials(deepcopy=False, states=(self.optuna.trial.TrialState.RUNNING,)):
            if shared:
                beat = t.user_attrs.get("heartbeat") or (t.datetime_start.timestamp() if t.datetime_start else now)
                if now - beat < self.args.stale_after:
                    continue
            try:
                self.storage.set_trial_user_attr(t._trial_id, "interrupted", True)
                if not self.storage.set_trial_state_values(t._trial_id, self.optuna.trial.TrialState.FAIL):
                    continue
            except Exception:  # another worker got there first
                continue
            config = t.user_attrs.get("config")
            if config is not None:
                self.retry(t.number, config)
            print(f"explore: trial {t.number} was interrupted: its configuration is queued again", file=sys.stderr)

    def retry(self, number, config):
        params = {p.name: config[p.name] for p in self.varied if p.name in config}
        self.study.enqueue_trial(params, user_attrs={"retry_of": number})

    def enqueue_grid(self):
        """--grid: every point not evaluated, queued or running, queued in the grid's order."""
        covered = set()
        for t in self.trials():
            if self.evaluation(t) or t.state.name == "RUNNING":
                cfg = t.user_attrs.get("config")
                if cfg:
                    covered.add(config_key(cfg))
            elif t.state.name == "WAITING":
                covered.add(config_key(full_config(self.space, t.system_attrs.get("fixed_params", {}))))
        n = 0
        for point in self.grid:
            if config_key(full_config(self.space, point)) not in covered:
                self.study.enqueue_trial(point)
                n += 1
        return n

    # ---- the search loop
    def ask(self):
        trial = self.study.ask()
        values = {p.name: p.suggest(trial) for p in self.varied}
        return trial, full_config(self.space, values)

    def random_unevaluated(self, taken, salt):
        """A configuration drawn uniformly (log-uniformly for "log" ranges) that is not in
        `taken`, or None after 1000 draws; seeded by the seed and `salt` (a trial number)."""
        import random
        rng = random.Random(self.args.seed * 1000003 + salt)
        for _ in range(1000):
            values = {}
            for p in self.varied:
                if p.kind == "choice":
                    values[p.name] = rng.choice(p.values)
                elif p.log:
                    x = math.exp(rng.uniform(math.log(p.lo), math.log(p.hi + (1 if p.kind == "int" else 0))))
                    values[p.name] = min(p.hi, int(x)) if p.kind == "int" else min(p.hi, x)
                else:
                    values[p.name] = rng.randint(p.lo, p.hi) if p.kind == "int" else rng.uniform(p.lo, p.hi)
            if config_key(full_config(self.space, values)) not in taken:
                return values
        return None

    def refresh(self):
        """Reads the study; the evaluations it holds join the ledger. Returns every trial."""
        trials = self.trials()
        for t in trials:
            if t.number not in self.ledger and self.evaluation(t):
                self.ledger[t.number] = t
        return trials

    def run(self, shared):
        """Evaluates until the study holds the requested evaluations, the time budget is spent
        or a signal comes (loop.py). Returns a note why it stopped early, or None."""
        from .loop import Loop
        return Loop(self, shared).run_loop()

    def record(self, trial, config, ev, fidelity=TARGET):
        """Tells the study. With screening, the sampler learns from the screened figures; an
        evaluation at the target fidelity is kept in its trial, pruned for the sampler (its
        figures are on another scale)."""
        r = ev.result
        k = len(self.space.objectives)
        ok = r["outcome"] in ("complete", "infeasible") and "figures" in r
        values = [r["figures"][o] for o in self.space.objectives] if ok else [float("inf")] * k
        violations = r.get("violations") or [0.0] * len(self.space.constraints)
        evaluation = {"outcome": r["outcome"], "reason": r.get("reason", ""), "config": config,
                      "figures": r.get("figures"), "constraint_values": r.get("constraint_values", {}),
                      "violations": violations, "wall_s": round(ev.wall, 3),
                      "violations_all": violations + [0.0 if ok else FAILED_PENALTY],
                      "resolution": getattr(ev, "resolution", None) or self.space.resolution}
        trial.set_user_attr("evaluation", evaluation)
        if fidelity == TARGET and self.screen:
            told = self.study.tell(trial, state=self.optuna.trial.TrialState.PRUNED)
        else:
            told = self.study.tell(trial, values)
        self.persist(told.number)
        return told

    def add_to_front(self, t):
        """Keeps self.front: the feasible target-fidelity evaluations no other dominates."""
        e = self.evaluation(t)
        if e["outcome"] != "complete" or t.user_attrs.get("fidelity", TARGET) != TARGET:
            return
        objs = self.space.objectives
        p = [e["figures"][o] for o in objs]
        pts = [[self.evaluation(q)["figures"][o] for o in objs] for q in self.front]
        if any(dominates(q, p) or q == p for q in pts):
            return
        self.front = [q for q, qp in zip(self.front, pts) if not dominates(p, qp)] + [t]

    def progress(self, trial, config, ev, t0, fidelity=TARGET):
        r = ev.result
        if not self.front or self.front_size != len(self.ledger) - 1:
            self.front = []
            for t in self.ledger.values():
                self.add_to_front(t)
        else:
            self.add_to_front(trial)
        self.front_size = len(self.ledger)
        n = len(self.ledger)
        conf = " ".join(f"{p.name}={show(config[p.name])}" for p in self.varied)
        if "figures" in r:
            f = r["figures"]
            what = ", ".join(f"{f[o] * UNITS[o][0]:.4g} {UNITS[o][1]}" for o in OBJECTIVES)
            if r["outcome"] == "infeasible":
                what += f" [{r['reason']}]"
        else:
            what = r.get("reason", "")
            what = what if len(what) <= 110 else what[:107] + "..."
        if self.front:
            best = []
            for o in self.space.objectives:
                t = best_for(self, self.front, o)
                best.append(f"{self.evaluation(t)['figures'][o] * UNITS[o][0]:.4g} {UNITS[o][1]} (trial {t.number})")
            best_text = f"best {', '.join(best)}; front {len(self.front)}"
            if not self.args.worker:  # a worker has no reference point
                best_text += f", hypervolume {self.hypervolume([self.evaluation(t)['figures'] for t in self.front]):.4f}"
        else:
            best_text = "nothing feasible yet"
        elapsed = time.time() - t0
        of = "" if self.target >= UNBOUNDED else f"/{self.target}"
        tag = f" {fidelity}" if self.screen else ""
        print(f"explore: [{n}{of}] trial {trial.number}{tag} {r['outcome']:<10} "
              f"{conf}: {what} ({ev.wall:.1f} s) | {best_text} | {fmt_time(elapsed)}", flush=True)
        if n < 500 or time.time() - self.last_write > 2:  # a long search's file: rewritten every 2 s
            self.write_evaluations()

    # ---- figures
    def hypervolume(self, figures_list):
        """Hypervolume of the points (objective figures) within the reference point, each
        objective divided by its reference value: 0 (nothing better than the reference) to 1."""
        ref = self.reference_point
        pts = [[f[o] / ref[o] for o in self.space.objectives] for f in figures_list]
        return hypervolume(pts, [1.0] * len(self.space.objectives))

    def columns(self):
        return ["trial", "state", "reason"] + [p.name for p in self.space.params] + list(OBJECTIVES) + ["wall_s"]

    def row(self, t):
        e = self.evaluation(t)
        f = e.get("figures") or {}
        row = {"trial": t.number, "state": e["outcome"], "reason": e.get("reason", ""), "wall_s": e["wall_s"]}
        for p in self.space.params:
            v = e["config"].get(p.name, "")
            row[p.name] = json.dumps(v) if isinstance(v, (list, bool)) else v
        for o in OBJECTIVES:
            row[o] = repr(f[o]) if o in f else ""
        return row

    def write_evaluations(self):
        self.last_write = time.time()
        done = [self.ledger[n] for n in sorted(self.ledger)]
        atomic_write(os.path.join(self.out, "evaluations.csv"), csv_text(self.columns(), [self.row(t) for t in done]))


def best_for(run, trials, objective):
    """The trial lowest in one objective, ties broken by the other objectives in order."""
    order = [objective] + [o for o in run.space.objectives if o != objective]
    return min(trials, key=lambda t: [run.evaluation(t)["figures"][o] for o in order])


def pareto_trials(run, feasible):
    """The feasible evaluations no other one dominates (as good in every objective, better in
    one), by first objective; of two with the same figures, the first."""
    objs = run.space.objectives
    pts = [[run.evaluation(t)["figures"][o] for o in objs] for t in feasible]
    front = [t for i, t in enumerate(feasible)
             if not any(dominates(q, pts[i]) or (q == pts[i] and j < i) for j, q in enumerate(pts))]
    return sorted(front, key=lambda t: [run.evaluation(t)["figures"][o] for o in run.space.objectives])
