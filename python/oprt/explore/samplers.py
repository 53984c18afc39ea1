"""The portfolio sampler: a first generation spread over the space (a Latin hypercube: each
parameter's values, or equal slices of its range, dealt out evenly in a random order), then
Optuna's NSGA-II from it. NSGA-II's own first generation is uniformly random, and on a small
budget a random start can leave a whole region unseen."""
import math
import random


def portfolio_sampler(optuna, seed, population, constraints):
    from optuna.samplers.nsgaii._sampler import _GENERATION_KEY
    d = optuna.distributions

    class PortfolioSampler(optuna.samplers.NSGAIISampler):
        def __init__(self):
            super().__init__(seed=seed, constraints_func=constraints, population_size=population)
            self._lhs_rng = random.Random(seed)
            self._decks = {}
            self._dealt = 0

        def _deal(self, name, dist):
            """The next value of a parameter's deck (a new shuffled deck each generation's worth)."""
            k = self._dealt % population
            if k == 0 or name not in self._decks:
                if isinstance(dist, d.CategoricalDistribution):
                    deck = [dist.choices[i % len(dist.choices)] for i in range(population)]
                else:
                    deck = [(i + self._lhs_rng.random()) / population for i in range(population)]
                self._lhs_rng.shuffle(deck)
                self._decks[name] = deck
            v = self._decks[name][k]
            if isinstance(dist, d.CategoricalDistribution):
                return v
            lo, hi = dist.low, dist.high
            if isinstance(dist, d.IntDistribution):
                hi += 1  # the slice of the last value
            x = math.exp(math.log(lo) + v * (math.log(hi) - math.log(lo))) if dist.log else lo + v * (hi - lo)
            if isinstance(dist, d.IntDistribution):
                return min(dist.high, int(math.floor(x)))
            return min(dist.high, x)

        def sample_relative(self, study, trial, search_space):
            generation, _ = self._collect_parent_population(study)
            if generation >= 0 or not search_space:
                return super().sample_relative(study, trial, search_space)
            study._storage.set_trial_system_attr(trial._trial_id, _GENERATION_KEY, 0)
            params = {name: self._deal(name, dist) for name, dist in search_space.items()}
            self._dealt += 1
            return params

    return PortfolioSampler()
