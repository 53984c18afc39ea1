"""Fidelities of a search: cheap screening, the space's resolution (the target), their agreement,
and the time budget (how long each phase may run, and how the time went)."""
import math
import re
import time

from .common import UsageError

SCREEN, TARGET = "screen", "target"
UNBOUNDED = 10 ** 9  # the evaluations of a search bounded by its time budget only


# ------------------------------------------------------------------------------- the budget
def parse_duration(text, option="--budget"):
    """'90s', '15m', '1h', '1.5h', '600' (seconds) -> seconds."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*(s|m|min|h)?\s*", text or "")
    if not m or float(m.group(1)) <= 0:
        raise UsageError(f"{option} {text}: expected a duration such as 90s, 15m or 1h")
    return float(m.group(1)) * {"s": 1, None: 1, "m": 60, "min": 60, "h": 3600}[m.group(2)]


class Clock:
    """The command's time: a budget (or none), the search's share of it, and each phase's seconds.
    With a budget the search stops proposing at `search_end` (the budget less a share kept for the
    confirmation at `at`) and stops what is still running at `hard_end`."""

    CONFIRM_SHARE = 0.15

    def __init__(self, budget_s):
        self.start = time.time()
        self.budget = budget_s
        self.search_end = self.hard_end = None
        if budget_s:
            self.search_end = self.start + budget_s * (1 - self.CONFIRM_SHARE)
            self.hard_end = self.start + budget_s * (1 - self.CONFIRM_SHARE / 2)
        self.phases = {}  # phase -> seconds of the command's time

    def past(self, hard=False):
        end = self.hard_end if hard else self.search_end
        return end is not None and time.time() >= end

    def add(self, phase, seconds):
        self.phases[phase] = self.phases.get(phase, 0.0) + seconds

    def elapsed(self):
        return time.time() - self.start


# ---------------------------------------------------------------------------------- fidelities
def pixels(resolution):
    m = re.fullmatch(r"(\d+)x(\d+)", resolution or "")
    return int(m.group(1)) * int(m.group(2)) if m else None


def screen_resolution(option, space_resolution):
    """The screening resolution: `--screen WxH`, `none` (no screening), or by default the space's
    resolution divided by 4 per side (no screening below 64x64 or without a resolution)."""
    if option == "none":
        return None
    if option:
        if not re.fullmatch(r"[1-9]\d*x[1-9]\d*", option):
            raise UsageError(f"--screen {option}: expected WxH (such as 32x32) or none")
        if space_resolution and pixels(option) >= pixels(space_resolution):
            raise UsageError(f"--screen {option}: not cheaper than the space's resolution {space_resolution}")
        return option
    m = re.fullmatch(r"(\d+)x(\d+)", space_resolution or "")
    if not m or min(int(m.group(1)), int(m.group(2))) < 64:
        return None
    return f"{int(m.group(1)) // 4}x{int(m.group(2)) // 4}"


def dominates(p, q):
    return all(a <= b for a, b in zip(p, q)) and any(a < b for a, b in zip(p, q))


def nondominated_ranks(points):
    """Each point's front number (0: not dominated; 1: dominated only by front 0; ...)."""
    rank = [None] * len(points)
    left = set(range(len(points)))
    r = 0
    while left:
        front = {i for i in left if not any(dominates(points[j], points[i]) for j in left if j != i)}
        for i in front:
            rank[i] = r
        left -= front
        r += 1
    return rank


def promotions(run, fraction):
    """Screened configurations to price at the target fidelity (successive halving's promotion):
    every screened one that meets the bounds and that no other dominates, and the best `fraction`
    of them by non-dominated rank (then frame time), less those already promoted. Returns configs."""
    objs = run.space.objectives
    screened = [t for t in run.ledger.values() if t.user_attrs.get("fidelity") == SCREEN
                and run.evaluation(t)["outcome"] == "complete"]
    if not screened:
        return []
    pts = [[run.evaluation(t)["figures"][o] for o in objs] for t in screened]
    ranks = nondominated_ranks(pts)
    order = sorted(range(len(screened)), key=lambda i: (ranks[i], pts[i]))
    keep = max(sum(1 for r in ranks if r == 0), math.ceil(fraction * len(screened)))
    return [run.evaluation(screened[i])["config"] for i in order[:keep]]


def ranked(values):
    """Mid-ranks (ties share the mean rank)."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    ranks = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            ranks[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return ranks


def spearman(x, y):
    rx, ry = ranked(x), ranked(y)
    n = len(x)
    mx, my = sum(rx) / n, sum(ry) / n
    cov = sum((a - mx) * (b - my) for a, b in zip(rx, ry))
    sx = math.sqrt(sum((a - mx) ** 2 for a in rx))
    sy = math.sqrt(sum((b - my) ** 2 for b in ry))
    return cov / (sx * sy) if sx and sy else float("nan")


def kendall(x, y):
    """Kendall's tau-b."""
    conc = disc = tx = ty = 0
    n = len(x)
    for i in range(n):
        for j in range(i + 1, n):
            a, b = x[i] - x[j], y[i] - y[j]
            if a == 0 and b == 0:
                continue
            if a == 0:
                tx += 1
            elif b == 0:
                ty += 1
            elif (a > 0) == (b > 0):
                conc += 1
            else:
                disc += 1
    d = math.sqrt((conc + disc + tx) * (conc + disc + ty))
    return (conc - disc) / d if d else float("nan")


def fidelity_error(run, screen_res):
    """The screening's agreement with the target fidelity on the configurations priced at both:
    rows per objective (n, Spearman, Kendall, mean and largest relative error of the screening's
    figure scaled by the pixel ratio, for frame time and energy), and the pairs themselves."""
    from .common import config_key
    by_fid = {SCREEN: {}, TARGET: {}}
    for t in run.ledger.values():
        e = run.evaluation(t)
        if e.get("figures") and e["outcome"] != "failed" and "refused" not in e.get("reason", ""):
            by_fid[t.user_attrs.get("fidelity", TARGET)][config_key(e["config"])] = e["figures"]
    pairs = [(s, by_fid[TARGET][k]) for k, s in by_fid[SCREEN].items() if k in by_fid[TARGET]]
    ratio = pixels(run.space.resolution) / pixels(screen_res)
    rows = []
    for o in run.space.objectives:
        if len(pairs) < 3:
            break
        x, y = [p[0][o] for p in pairs], [p[1][o] for p in pairs]
        scale = 1.0 if o == "area_mm2" else ratio
        rel = [abs(a * scale - b) / abs(b) * 100 for a, b in zip(x, y) if b]
        rows.append({"objective": o, "pairs": len(pairs), "spearman": spearman(x, y), "kendall": kendall(x, y),
                     "scale": scale, "mean_rel_error_pct": sum(rel) / len(rel) if rel else float("nan"),
                     "max_rel_error_pct": max(rel) if rel else float("nan")})
    return rows
