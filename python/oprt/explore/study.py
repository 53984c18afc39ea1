"""A search in an output folder: the study, its evaluations and the loop that asks, evaluates and tells."""
import json
import math
import os
import sys
import time

from ..files import atomic_write, csv_text
from ..pareto import hypervolume
from ..values import fmt_time, show
from .common import OBJECTIVES, UNITS, FAILED_PENALTY, HEARTBEAT_S, UsageError, finite_size, full_config, config_key, reuse_key
from .evaluate import Evaluation, Reused
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

    # ---- the study
    def sampler(self, seed):
        optuna = self.optuna
        if self.args.grid:
            return optuna.samplers.RandomSampler(seed=seed)
        n_constraints = len(self.space.constraints) + 1

        def constraints(trial):
            return trial.user_attrs.get("evaluation", {}).get("violations_all", [0.0] * n_constraints)

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
        self.study = self.optuna.create_study(storage=self.storage, study_name="explore", load_if_exists=True,
                                              directions=["minimize"] * len(self.space.objectives),
                                              sampler=self.sampler(seed))
        if len(self.study.directions) != len(self.space.objectives):
            raise UsageError(f"--out {self.args.out}: its study has {len(self.study.directions)} objectives, "
                             f"the space {len(self.space.objectives)}")

    def trials(self):
        return self.study.get_trials(deepcopy=False)

    @staticmethod
    def evaluation(t):
        """The evaluation a trial holds, or None (duplicates, surplus, interrupted, running)."""
        if t.state.name != "COMPLETE":
            return None
        return t.user_attrs.get("evaluation")

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
        """Evaluates until the study holds the requested evaluations (or a signal). Returns a
        note why it stopped early, or None. Locally the ledger of evaluations is kept here (the
        study is read once); with a shared study, it is read again before each new trial."""
        optuna = self.optuna
        target = self.target
        inflight = {}  # trial number -> (trial, config, evaluation)
        duplicates_in_a_row = 0
        last_beat = time.time()
        note = None
        t0 = time.time()
        size = finite_size(self.space)
        self.refresh()
        known = {config_key(self.evaluation(t)["config"]): n for n, t in self.ledger.items()}
        running_others = []
        try:
            while True:
                if self.stop_signal:
                    break
                finished = [n for n, (_, _, ev) in inflight.items() if ev.poll()]
                for n in finished:
                    trial, config, ev = inflight.pop(n)
                    self.ledger[n] = self.record(trial, config, ev)
                    known[config_key(config)] = n
                    self.progress(self.ledger[n], config, ev, t0)
                if shared and time.time() - last_beat > HEARTBEAT_S:
                    for trial, _, _ in inflight.values():
                        trial.set_user_attr("heartbeat", time.time())
                    last_beat = time.time()
                    self.recover(shared=True)
                launched = False
                while len(inflight) < self.jobs and not self.stop_signal and note is None:
                    if shared:
                        trials = self.refresh()
                        for n, t in self.ledger.items():
                            known.setdefault(config_key(self.evaluation(t)["config"]), n)
                        running_others = [t for t in trials if t.state.name == "RUNNING" and t.number not in inflight]
                        if self.args.grid and not any(t.state.name == "WAITING" for t in trials):
                            break
                    if len(self.ledger) + len(inflight) + len(running_others) >= target:
                        break
                    if size is not None and len(known) >= size and not self.args.grid:
                        note = f"the space has only {size} configurations, and every one is evaluated"
                        break
                    trial, config = self.ask()
                    key = config_key(config)
                    if self.args.grid and "fixed_params" not in self.study._storage.get_trial(trial._trial_id).system_attrs:
                        trial.set_user_attr("surplus", True)  # the queue ran dry (another worker took the last)
                        self.study.tell(trial, state=optuna.trial.TrialState.PRUNED)
                        break
                    same = known.get(key)
                    if same is None:
                        same = next((n for n, (_, c, _) in inflight.items() if config_key(c) == key), None)
                        if same is None:
                            same = next((t.number for t in running_others
                                         if config_key(t.user_attrs.get("config") or {}) == key), None)
                    if same is not None:
                        # Already evaluated (or being evaluated): not evaluated again, not counted.
                        # A sampler that has converged proposes the same configurations again and
                        # again (TPE learns nothing from a pruned trial): the next trial is then a
                        # random configuration not evaluated yet.
                        trial.set_user_attr("duplicate_of", same)
                        self.study.tell(trial, state=optuna.trial.TrialState.PRUNED)
                        duplicates_in_a_row += 1
                        taken = set(known) | {config_key(c) for _, c, _ in inflight.values()}
                        fresh = self.random_unevaluated(taken, trial.number)
                        if fresh is not None:
                            self.study.enqueue_trial(fresh, user_attrs={"random_after_duplicate": trial.number})
                        elif size is not None:
                            note = f"the space has only {size} configurations, and every one is evaluated"
                        if duplicates_in_a_row >= self.args.max_duplicates:
                            note = (f"the sampler proposed {duplicates_in_a_row} configurations in a row that were "
                                    "already evaluated: the search has converged")
                        continue
                    duplicates_in_a_row = 0
                    trial.set_user_attr("config", config)
                    if shared:
                        trial.set_user_attr("heartbeat", time.time())
                        # Surplus: several workers asked at once for the last evaluations.
                        ahead = [t for t in self.trials() if (t.state.name == "RUNNING" or self.evaluation(t))
                                 and t.number < trial.number]
                        if len(ahead) >= target:
                            trial.set_user_attr("surplus", True)
                            self.study.tell(trial, state=optuna.trial.TrialState.PRUNED)
                            break
                    if self.reused and reuse_key(self.space, config) in self.reused:
                        ev = Reused(self.reused[reuse_key(self.space, config)])
                    else:
                        ev = Evaluation(self, trial.number, config)
                    inflight[trial.number] = (trial, config, ev)
                    launched = True
                if not inflight:  # every slot was free and nothing could start
                    if len(self.ledger) >= target or note is not None:
                        break
                    if not shared:
                        if self.args.grid:
                            break  # a grid point lost its queued trial: the next run queues it again
                        continue
                    trials = self.refresh()
                    if not any(t.state.name == "RUNNING" for t in trials):
                        if self.args.grid and not any(t.state.name == "WAITING" for t in trials):
                            break
                        continue
                    time.sleep(1)  # other workers are evaluating the last ones
                    self.recover(shared=True)
                    continue
                if not finished and not launched:
                    time.sleep(0.02)
        finally:
            for n, (trial, config, ev) in inflight.items():  # interrupted: lost, queued again
                ev.stop()
                try:
                    trial.set_user_attr("interrupted", True)
                    self.study.tell(trial, state=optuna.trial.TrialState.FAIL)
                    self.retry(n, config)
                except Exception as e:  # the store itself failed: the next run recovers the trial
                    print(f"explore: trial {n}: could not record the interruption ({e})", file=sys.stderr)
        return note

    def record(self, trial, config, ev):
        r = ev.result
        k = len(self.space.objectives)
        ok = r["outcome"] in ("complete", "infeasible") and "figures" in r
        values = [r["figures"][o] for o in self.space.objectives] if ok else [float("inf")] * k
        violations = r.get("violations") or [0.0] * len(self.space.constraints)
        evaluation = {"outcome": r["outcome"], "reason": r.get("reason", ""), "config": config,
                      "figures": r.get("figures"), "constraint_values": r.get("constraint_values", {}),
                      "violations": violations, "wall_s": round(ev.wall, 3),
                      "violations_all": violations + [0.0 if ok else FAILED_PENALTY]}
        trial.set_user_attr("evaluation", evaluation)
        return self.study.tell(trial, values)

    def progress(self, trial, config, ev, t0):
        r = ev.result
        done = list(self.ledger.values())
        n = len(done)
        names = [p.name for p in self.varied]
        conf = " ".join(f"{k}={show(config[k])}" for k in names)
        if "figures" in r:
            f = r["figures"]
            what = ", ".join(f"{f[o] * UNITS[o][0]:.4g} {UNITS[o][1]}" for o in OBJECTIVES)
            if r["outcome"] == "infeasible":
                what += f" [{r['reason']}]"
        else:
            what = r.get("reason", "")
            what = what if len(what) <= 110 else what[:107] + "..."
        feasible = [t for t in done if self.evaluation(t)["outcome"] == "complete"]
        if feasible:
            best = []
            for o in self.space.objectives:
                t = best_for(self, feasible, o)
                best.append(f"{self.evaluation(t)['figures'][o] * UNITS[o][0]:.4g} {UNITS[o][1]} (trial {t.number})")
            front = pareto_trials(self, feasible)
            best_text = f"best {', '.join(best)}; front {len(front)}"
            if not self.args.worker:  # a worker has no reference point
                best_text += f", hypervolume {self.hypervolume([self.evaluation(t)['figures'] for t in front]):.4f}"
        else:
            best_text = "nothing feasible yet"
        elapsed = time.time() - t0
        print(f"explore: [{n:{len(str(self.target))}}/{self.target}] trial {trial.number} {r['outcome']:<10} "
              f"{conf}: {what} ({ev.wall:.1f} s) | {best_text} | {fmt_time(elapsed)}", flush=True)
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
        done = [self.ledger[n] for n in sorted(self.ledger)]
        atomic_write(os.path.join(self.out, "evaluations.csv"), csv_text(self.columns(), [self.row(t) for t in done]))


def best_for(run, trials, objective):
    """The trial lowest in one objective, ties broken by the other objectives in order."""
    order = [objective] + [o for o in run.space.objectives if o != objective]
    return min(trials, key=lambda t: [run.evaluation(t)["figures"][o] for o in order])


def pareto_trials(run, feasible):
    """The feasible evaluations no other one dominates (Optuna's own test), by first objective."""
    from optuna.study._multi_objective import _get_pareto_front_trials_by_trials
    front = _get_pareto_front_trials_by_trials(list(feasible), run.study.directions)
    return sorted(front, key=lambda t: [run.evaluation(t)["figures"][o] for o in run.space.objectives])
