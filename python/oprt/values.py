"""Small helpers for values read from JSON and shown to people."""
import json
import math


def is_integer(v):
    """A JSON integer (not true/false)."""
    return isinstance(v, int) and not isinstance(v, bool)


def is_number(v):
    """A finite JSON number (not true/false)."""
    return (is_integer(v) or isinstance(v, float)) and math.isfinite(v)


def show(v):
    """A value as a space file writes it: text as it is, anything else as JSON."""
    return json.dumps(v) if not isinstance(v, str) else v


def fmt_time(s):
    """Seconds as M:SS, or H:MM:SS from an hour on."""
    s = int(s)
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"
