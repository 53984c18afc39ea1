"""oprt's statistics files, and the correlation the result scripts print.

stats.json: the run's figures (frames, units, area, energy; docs/stats.md). stats.csv: one row
per frame and unit, numbers where the text is a number.
"""
import csv
import json
import math
import os


def read_stats(folder):
    """stats.json of an output folder (or the file itself) as a dict."""
    path = os.path.join(folder, "stats.json") if os.path.isdir(folder) else folder
    with open(path) as f:
        return json.load(f)


def frame_rays(frame):
    """Every ray a frame of stats.json traced, whatever its kind (primary, shadow, and the
    reflection and refraction rays listed when the frame has any)."""
    return sum(frame["rays"].values())


def number(text):
    """A CSV cell as an int, else a float, else the text as it is ('' stays '')."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def read_stats_csv(folder):
    """stats.csv of an output folder (or the file itself): a list of rows {column: value}."""
    path = os.path.join(folder, "stats.csv") if os.path.isdir(folder) else folder
    with open(path, newline="") as f:
        return [{k: number(v) for k, v in row.items()} for row in csv.DictReader(f)]


def pearson(xs, ys):
    """Pearson's correlation of two equally long series. NaN where it is undefined: fewer than
    two points, a series without spread (every value the same), or a NaN in either series."""
    n = len(xs)
    if n != len(ys):
        raise ValueError(f"pearson: {n} values against {len(ys)}")
    if n < 2:
        return float("nan")
    if any(math.isnan(v) for v in (*xs, *ys)) or min(xs) == max(xs) or min(ys) == max(ys):
        return float("nan")  # (spread is judged on the values: a mean's rounding is not spread)
    mx, my = sum(xs) / n, sum(ys) / n
    sxy = sum((a - mx) * (b - my) for a, b in zip(xs, ys))
    sxx = sum((a - mx) ** 2 for a in xs)
    syy = sum((b - my) ** 2 for b in ys)
    return sxy / math.sqrt(sxx * syy)
