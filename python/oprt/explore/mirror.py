"""A local search's study in memory, written through to its file (DIR/study.db) trial by trial.

Optuna's RDBStorage commits every parameter a trial suggests and every attribute it sets, some
sixty SQLite transactions a trial: 0.3 s a trial on a loaded machine, more than the evaluation
it records once oprt prices configurations in batches. The sampler works on an in-memory study;
each trial reaches the file when it starts (one transaction: the trial as it is, RUNNING, with its
parameters) and when it ends (its attributes and state), in trial-number order, so that the file's
trial numbers are the memory's. A kill at any moment leaves the file as consistent as before
(its transactions), with the trials in flight RUNNING for the next run to recover; the trials
still queued (WAITING) are written when the search ends. Shared studies (--storage, Slurm) keep
Optuna's own storage: their workers meet in it."""


class Mirror:
    def __init__(self, optuna, durable_storage, memory_study):
        self.optuna = optuna
        self.durable = durable_storage
        self.durable_study_id = durable_storage.get_study_id_from_name("explore")
        self.memory = memory_study
        self.ids = {}  # trial number -> the file's trial id
        for t in durable_storage.get_all_trials(self.durable_study_id, deepcopy=False):
            self.ids[t.number] = t._trial_id
            memory_study.add_trial(t)

    def frozen(self, number):
        return self.memory._storage.get_trial(self.memory._storage.get_trial_id_from_study_id_trial_number(
            self.memory._study_id, number))

    def write(self, number):
        """The memory's trial `number` into the file: created (with every trial before it not yet
        there), or brought up to date."""
        for n in range(len(self.ids), number):  # earlier ones (queued) first, as they are
            self.create(self.frozen(n))
        t = self.frozen(number)
        if number not in self.ids:
            self.create(t)
            return
        tid = self.ids[number]
        old = self.durable.get_trial(tid)
        TS = self.optuna.trial.TrialState
        if old.state == TS.WAITING and t.state != TS.WAITING:
            self.durable.set_trial_state_values(tid, TS.RUNNING)
            old = self.durable.get_trial(tid)
        for name, value in t.params.items():
            if name not in old.params:
                dist = t.distributions[name]
                self.durable.set_trial_param(tid, name, dist.to_internal_repr(value), dist)
        for key, value in t.system_attrs.items():
            if old.system_attrs.get(key) != value:
                self.durable.set_trial_system_attr(tid, key, value)
        for key, value in t.user_attrs.items():
            if old.user_attrs.get(key) != value:
                self.durable.set_trial_user_attr(tid, key, value)
        if t.state != old.state and t.state.is_finished():
            self.durable.set_trial_state_values(tid, t.state, t.values)

    def create(self, t):
        tid = self.durable.create_new_trial(self.durable_study_id, template_trial=t)
        number = self.durable.get_trial_number_from_id(tid)
        if number != t.number:
            raise RuntimeError(f"study file out of step: trial {t.number} written as {number}")
        self.ids[t.number] = tid

    def flush(self):
        """Every trial the memory holds that the file does not (the queued ones at the end)."""
        n = len(self.memory._storage.get_all_trials(self.memory._study_id, deepcopy=False))
        if n > len(self.ids):
            self.write(n - 1)
