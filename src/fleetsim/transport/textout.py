"""What the tools print: messages as rostopic-style YAML, rates as ``rostopic hz`` reports them,
and YAML typed on a command line read into messages."""

from __future__ import annotations

import itertools
import math
from collections import deque
from typing import Any

import yaml

from fleetsim.errors import MessageError


class _Dumper(yaml.SafeDumper):
    pass


def _list(dumper: yaml.SafeDumper, data: list) -> Any:
    flow = all(not isinstance(v, dict | list) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_Dumper.add_representer(list, _list)


def yaml_text(data: Any) -> str:
    """Block YAML with sequences of numbers on one line (``ranges: [1.0, 2.0]``), as rostopic."""
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, default_flow_style=False, width=100)


def message_yaml(msg: Any, no_arrays: bool = False) -> str:
    """One message as the YAML document ``rostopic echo`` prints (without the ``---``)."""
    from fleetsim.msgs import to_dict

    data = to_dict(msg)
    if no_arrays:
        data = _drop_arrays(data)
    return yaml_text(data)


def _drop_arrays(d: Any) -> Any:
    if isinstance(d, dict):
        return {k: _drop_arrays(v) for k, v in d.items()}
    if isinstance(d, list) and len(d) > 0 and not isinstance(d[0], dict):
        return f"<array type: {type(d[0]).__name__}, length: {len(d)}>"
    if isinstance(d, list):
        return [_drop_arrays(v) for v in d]
    return d


def parse_yaml_arg(text: str | None, what: str) -> Any:
    """YAML typed on a command line; a parse error names ``what`` and the line/column."""
    if text is None or not text.strip():
        return None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        raise MessageError(f"{what}: the YAML does not parse{at}: {problem}") from None


def fill_now(data: Any, now: float) -> Any:
    """Replace ``stamp: now`` anywhere in ``data`` by the sim time ``now`` (rostopic's ``now``)."""
    if isinstance(data, dict):
        return {
            k: (now if k == "stamp" and v == "now" else fill_now(v, now)) for k, v in data.items()
        }
    if isinstance(data, list):
        return [fill_now(v, now) for v in data]
    return data


class RateStats:
    """``rostopic hz``: average rate, min/max/std-dev of the period over the last ``window``
    messages, from arrival times in seconds (sim time when the simulation publishes /clock)."""

    def __init__(self, window: int = 1000) -> None:
        if window < 2:
            raise MessageError(f"hz window must be at least 2 messages, got {window}")
        self.times: deque[float] = deque(maxlen=window)

    def add(self, t: float) -> None:
        self.times.append(t)

    def report(self) -> dict | None:
        """``{"rate", "min", "max", "std", "window"}``, or None before two messages."""
        if len(self.times) < 2:
            return None
        t = list(self.times)
        periods = [b - a for a, b in itertools.pairwise(t)]
        mean = (t[-1] - t[0]) / len(periods)
        if mean <= 0.0:
            return None
        std = math.sqrt(sum((p - mean) ** 2 for p in periods) / len(periods))
        return {
            "rate": 1.0 / mean,
            "min": min(periods),
            "max": max(periods),
            "std": std,
            "window": len(t),
        }

    @staticmethod
    def format(r: dict) -> str:
        return (
            f"average rate: {r['rate']:.3f}\n"
            f"\tmin: {r['min']:.3f}s max: {r['max']:.3f}s std dev: {r['std']:.5f}s "
            f"window: {r['window']}"
        )
