"""The search loop: ask the sampler, price each configuration (screening first when the search
screens, the promoted ones at the target fidelity), tell the study, until the evaluations or the
time budget are spent."""
import sys
import time

from .common import HEARTBEAT_S, config_key, finite_size, reuse_key
from .batch import Groups
from .evaluate import Evaluation, Reused
from .fidelity import SCREEN, TARGET, promotions


class Loop:
    """One run of the loop: what is in flight, what is known per fidelity."""

    def __init__(self, run, shared):
        self.run, self.shared = run, shared
        self.inflight = {}  # trial number -> (trial, config, evaluation, fidelity)
        self.duplicates_in_a_row = 0
        self.note = None
        self.size = finite_size(run.space)
        run.refresh()
        self.known = {SCREEN: {}, TARGET: {}}  # fidelity -> config key -> trial number
        for n, t in run.ledger.items():
            self.known[fidelity_of(t)][config_key(run.evaluation(t)["config"])] = n
        self.running_others = []
        self.screened_since = 0
        self.groups = Groups(run, run.args.group)
        self.capacity = run.jobs * (self.groups.size if self.groups.usable() else 1)

    def evaluated(self):
        """Configurations priced at the fidelity the sampler proposes for."""
        return self.known[SCREEN if self.run.screen else TARGET]

    def finish(self, n):
        run = self.run
        trial, config, ev, fid = self.inflight.pop(n)
        run.ledger[n] = run.record(trial, config, ev, fid)
        self.known[fid][config_key(config)] = n
        run.progress(run.ledger[n], config, ev, run.clock.start, fid)
        if fid == SCREEN:
            self.screened_since += 1
            if self.screened_since >= run.rung:
                self.promote()

    def promote(self):
        """Successive halving: the best screened configurations queued at the target fidelity."""
        run = self.run
        self.screened_since = 0
        queued = {config_key(c) for _, c, _, f in self.inflight.values() if f == TARGET}
        n = 0
        for config in promotions(run, run.args.promote):
            key = config_key(config)
            if key in self.known[TARGET] or key in queued or key in run.promoted:
                continue
            run.promoted.add(key)
            params = {p.name: config[p.name] for p in run.varied}
            run.study.enqueue_trial(params, user_attrs={"fidelity": TARGET})
            n += 1
        return n

    def duplicate(self, trial, key):
        """The trial number that already holds (or is pricing) this configuration, or None."""
        fid_known = self.evaluated()
        same = fid_known.get(key)
        if same is None:
            same = next((n for n, (_, c, _, f) in self.inflight.items() if config_key(c) == key
                         and (f == SCREEN) == bool(self.run.screen)), None)
        if same is None:
            same = next((t.number for t in self.running_others
                         if config_key(t.user_attrs.get("config") or {}) == key), None)
        return same

    def on_duplicate(self, trial, same):
        # Already evaluated (or being evaluated): not evaluated again, not counted. A sampler
        # that has converged proposes the same configurations again and again (TPE learns
        # nothing from a pruned trial): the next trial is then a random configuration not
        # evaluated yet.
        run = self.run
        trial.set_user_attr("duplicate_of", same)
        run.study.tell(trial, state=run.optuna.trial.TrialState.PRUNED)
        run.persist(trial.number)
        self.duplicates_in_a_row += 1
        taken = set(self.evaluated()) | {config_key(c) for _, c, _, _ in self.inflight.values()}
        fresh = run.random_unevaluated(taken, trial.number)
        if fresh is not None:
            run.study.enqueue_trial(fresh, user_attrs={"random_after_duplicate": trial.number})
        elif self.size is not None:
            self.note = f"the space has only {self.size} configurations, and every one is evaluated"
        if self.duplicates_in_a_row >= run.args.max_duplicates:
            self.note = (f"the sampler proposed {self.duplicates_in_a_row} configurations in a row that were "
                         "already evaluated: the search has converged")

    def start(self, trial, config, fid):
        run = self.run
        run.persist(trial.number)  # in the study's file as RUNNING before oprt starts
        resolution = run.screen if fid == SCREEN else None
        key = reuse_key(run.space, config) + "@" + (resolution or "")
        if run.reused and key in run.reused:
            ev = Reused(run.reused[key])
            ev.resolution = resolution
        elif self.groups.usable():
            ev = self.groups.add(trial.number, config, resolution)
        else:
            ev = Evaluation(run, trial.number, config, resolution=resolution)
        self.inflight[trial.number] = (trial, config, ev, fid)

    def launch_one(self):
        """Asks for one trial and starts it; False when nothing more may start now."""
        run = self.run
        optuna = run.optuna
        if self.shared:
            trials = run.refresh()
            for n, t in run.ledger.items():
                self.known[fidelity_of(t)].setdefault(config_key(run.evaluation(t)["config"]), n)
            self.running_others = [t for t in trials if t.state.name == "RUNNING" and t.number not in self.inflight]
            if run.args.grid and not any(t.state.name == "WAITING" for t in trials):
                return False
        if len(run.ledger) + len(self.inflight) + len(self.running_others) >= run.target:
            return False
        if self.size is not None and len(self.evaluated()) >= self.size and not run.args.grid:
            self.note = f"the space has only {self.size} configurations, and every one is evaluated"
            return False
        trial, config = run.ask()
        fid = TARGET if not run.screen or trial.user_attrs.get("fidelity") == TARGET else SCREEN
        key = config_key(config)
        if run.args.grid and "fixed_params" not in run.study._storage.get_trial(trial._trial_id).system_attrs:
            trial.set_user_attr("surplus", True)  # the queue ran dry (another worker took the last)
            run.study.tell(trial, state=optuna.trial.TrialState.PRUNED)
            return False
        same = self.known[TARGET].get(key) if fid == TARGET and run.screen else self.duplicate(trial, key)
        if same is not None:
            self.on_duplicate(trial, same)
            return True
        self.duplicates_in_a_row = 0
        trial.set_user_attr("config", config)
        trial.set_user_attr("fidelity", fid)
        if self.shared:
            trial.set_user_attr("heartbeat", time.time())
            # Surplus: several workers asked at once for the last evaluations.
            ahead = [t for t in run.trials() if (t.state.name == "RUNNING" or run.evaluation(t))
                     and t.number < trial.number]
            if len(ahead) >= run.target:
                trial.set_user_attr("surplus", True)
                run.study.tell(trial, state=optuna.trial.TrialState.PRUNED)
                return False
        self.start(trial, config, fid)
        return True

    def idle(self):
        """Nothing in flight and nothing could start: True to stop the loop."""
        run = self.run
        if len(run.ledger) >= run.target or self.note is not None or run.clock.past():
            return True
        if not self.shared:
            return bool(run.args.grid)  # a grid point lost its queued trial: the next run queues it again
        trials = run.refresh()
        if not any(t.state.name == "RUNNING" for t in trials):
            return bool(run.args.grid and not any(t.state.name == "WAITING" for t in trials))
        time.sleep(1)  # other workers are evaluating the last ones
        run.recover(shared=True)
        return False

    def run_loop(self):
        """Evaluates until the study holds the requested evaluations, the budget is spent or a
        signal comes. Returns a note why it stopped early, or None."""
        run = self.run
        last_beat = time.time()
        try:
            while not run.stop_signal:
                if run.clock.past(hard=True):
                    break  # what is still running is stopped below, failed and queued again
                finished = [n for n, (_, _, ev, _) in self.inflight.items() if ev.poll()]
                for n in finished:
                    self.finish(n)
                if self.shared and time.time() - last_beat > HEARTBEAT_S:
                    for trial, _, _, _ in self.inflight.values():
                        trial.set_user_attr("heartbeat", time.time())
                    last_beat = time.time()
                    run.recover(shared=True)
                launched, full = False, True
                while (len(self.inflight) < self.capacity and not run.stop_signal and self.note is None
                       and not run.clock.past()):
                    if not self.launch_one():
                        full = False
                        break
                    launched = True
                full = full and len(self.inflight) >= self.capacity
                self.groups.start_ready(more_coming=full)
                if not self.inflight:
                    if self.idle():
                        break
                    continue
                if not finished and not launched:
                    time.sleep(0.02)
        finally:
            self.stop_inflight()
            try:
                run.flush()  # the queued trials too
            except Exception as e:
                print(f"explore: could not write the queued trials to the study ({e})", file=sys.stderr)
        if run.clock.past() and self.note is None and len(run.ledger) < run.target:
            self.note = f"the time budget ({run.clock.budget:g} s) is spent"
        return self.note

    def stop_inflight(self):
        run = self.run
        for n, (trial, config, ev, fid) in self.inflight.items():  # interrupted: lost, queued again
            ev.stop()
            try:
                trial.set_user_attr("interrupted", True)
                run.study.tell(trial, state=run.optuna.trial.TrialState.FAIL)
                run.persist(n)
                if fid == TARGET and run.screen:
                    run.promoted.discard(config_key(config))
                    params = {p.name: config[p.name] for p in run.varied}
                    run.study.enqueue_trial(params, user_attrs={"fidelity": TARGET, "retry_of": n})
                else:
                    run.retry(n, config)
            except Exception as e:  # the store itself failed: the next run recovers the trial
                print(f"explore: trial {n}: could not record the interruption ({e})", file=sys.stderr)
        self.inflight.clear()


def fidelity_of(t):
    return t.user_attrs.get("fidelity", TARGET)
