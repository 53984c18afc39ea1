"""Pareto fronts and hypervolumes, every objective minimised.

A point dominates another when it is as small in every objective and smaller in one; the front
is the points no other point dominates. The hypervolume of a set of points within a reference
point is the volume of the region they dominate below the reference point (exact, by slicing).
"""


def dominates(a, b):
    """Whether point a (a sequence of objective values) dominates point b."""
    return all(x <= y for x, y in zip(a, b)) and any(x < y for x, y in zip(a, b))


def front_indices(points):
    """Indices of the points no other point dominates, in their input order."""
    return [i for i, p in enumerate(points) if not any(dominates(q, p) for q in points)]


def pareto_front(points, x, y):
    """The dicts of `points` no other beats in keys x and y (as small in both, smaller in one),
    sorted by x then y."""
    pairs = [(p[x], p[y]) for p in points]
    front = [points[i] for i in front_indices(pairs)]
    return sorted(front, key=lambda p: (p[x], p[y]))


def _area(points, ref):
    """Two objectives: the area dominated below ref, by a sweep along the first."""
    total, best_y = 0.0, ref[1]
    for x, y in sorted(points):
        if y < best_y:
            total += (ref[0] - x) * (best_y - y)
            best_y = y
    return total


def hypervolume(points, ref):
    """Exact hypervolume of `points` (sequences of 1, 2 or more objectives) below `ref`; points
    not below ref in every objective add nothing. Along the last objective, each slab between two
    consecutive values is the lower-dimensional hypervolume of the points at or below it."""
    points = [tuple(p) for p in points if all(v <= r for v, r in zip(p, ref))]
    if not points:
        return 0.0
    if len(ref) == 1:
        return ref[0] - min(p[0] for p in points)
    if len(ref) == 2:
        return _area(points, ref)
    cuts = sorted({p[-1] for p in points}) + [ref[-1]]
    total = 0.0
    for lo, hi in zip(cuts, cuts[1:]):
        if hi > lo:
            total += (hi - lo) * hypervolume([p[:-1] for p in points if p[-1] <= lo], ref[:-1])
    return total
