"""When each sensing plugin of the world falls due, and how the due ones are measured together.

A plugin with rate ``r`` fires at ``t0, t0 + 1/r, ...`` (phase kept, no drift); rate 0 fires
at every physics step. The due times of all sensing plugins are one array, so finding the due
ones is one comparison, and plugins of one class are measured in one call:

- ``measure(engine, t)``: one by one;
- ``measure_each(engine, plugins, t)`` (classmethod): many at once, each reading equal to what
  ``measure`` returns, placed in model order among the one-by-one readings;
- ``measure_batch(engine, plugins, t)`` (classmethod): a class at once, after those;
- lasers (``is_laser``): one batched cast (``LaserBatch``), last.

Plugins that never measure (the base ``Plugin.measure``) are left out.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit

from fleetsim.sim.plugins import base

SINGLE, EACH, BATCH, LASER = 0, 1, 2, 3  # how a sensing plugin is measured


def measures(p: base.Plugin) -> bool:
    """Whether a plugin produces readings at all."""
    cls = type(p)
    return (
        getattr(p, "is_laser", False)
        or hasattr(cls, "measure_batch")
        or hasattr(cls, "measure_each")
        or cls.measure is not base.Plugin.measure
    )


def measure_kind(p: base.Plugin) -> int:
    """``SINGLE``, ``EACH``, ``BATCH`` or ``LASER`` (see the module docstring)."""
    if getattr(p, "is_laser", False):
        return LASER
    if hasattr(type(p), "measure_batch"):
        return BATCH
    return EACH if hasattr(type(p), "measure_each") else SINGLE


def due_times_advanced(due_at: np.ndarray, period: np.ndarray, t: float) -> np.ndarray:
    """Advance the due times of the plugins due at ``t`` (in place); returns their indices.

    Parameters
    ----------
    due_at : (S,) sim time each plugin falls due next, s (0: never measured yet).
    period : (S,) update period, s (0: every physics step).
    t : current sim time, s.

    Returns
    -------
    (K,) int64 indices of the plugins due at ``t`` (``t + 1e-9 >= due_at``). Their next due
    time is one period after the previous one (phase kept), or one period after ``t`` when
    that has already passed or the plugin never fired.
    """
    return _advanced(due_at, period, float(t))[0]


@njit(cache=True)
def _advanced(due_at, period, t):
    """`due_times_advanced` and the earliest due time after it (inf for no plugin), compiled:
    the simulator asks at every physics step something falls due (NumPy's half-dozen calls
    cost ~10 us a step)."""
    idx = np.empty(due_at.shape[0], np.int64)
    k = 0
    earliest = np.inf
    for i in range(due_at.shape[0]):
        if t + 1e-9 >= due_at[i]:
            before, per = due_at[i], period[i]
            nxt = before + per if before > 0 else t + per
            due_at[i] = t + per if nxt <= t + 1e-9 else nxt
            idx[k] = i
            k += 1
        if due_at[i] < earliest:
            earliest = due_at[i]
    return idx[:k].copy(), earliest


class SensorSchedule:
    """The sensing plugins of an ``Engine``, their due times and measuring groups."""

    def __init__(self) -> None:
        self.plugins: list[base.Plugin] = []  # sensing plugins, in model order
        self.due_at = np.zeros(0)  # (S,) sim time each falls due next, s
        self.period = np.zeros(0)  # (S,) s
        self.next = 0.0  # earliest due time of any plugin, s
        self.groups: list[tuple[type, int, np.ndarray]] = []
        self.singles = np.zeros(0, np.int64)
        self.lasers = np.zeros(0, np.int64)

    def bind(self, plugins: list[base.Plugin]) -> None:
        """Take the plugin list after the set of models changed; plugins that stay keep their
        due times, new ones fall due at once."""
        kept = dict(zip(map(id, self.plugins), self.due_at.tolist()))
        self.plugins = [p for p in plugins if measures(p)]
        self.due_at = np.array([kept.get(id(p), 0.0) for p in self.plugins], float)
        rates = [p.update_rate for p in self.plugins]
        self.period = np.array([1.0 / r if r > 0 else 0.0 for r in rates], float)
        kind = np.array([measure_kind(p) for p in self.plugins], np.int64)
        groups: dict[type, list[int]] = {}
        for i, p in enumerate(self.plugins):
            if kind[i] in (EACH, BATCH):
                groups.setdefault(type(p), []).append(i)
        self.groups = [(c, int(kind[ids[0]]), np.array(ids, np.int64)) for c, ids in groups.items()]
        self.singles = np.flatnonzero(kind == SINGLE)
        self.lasers = np.flatnonzero(kind == LASER)
        self.next = 0.0

    def restart(self) -> None:
        """Every plugin falls due at once (sim time went back to zero)."""
        self.due_at[:] = 0.0
        self.next = 0.0

    def readings(self, engine, t: float) -> list[Any]:
        """Readings of the plugins due at ``t``: one-by-one and ``measure_each`` ones in model
        order, then ``measure_batch`` classes in order of their first due plugin, then lasers."""
        idx, self.next = _advanced(self.due_at, self.period, float(t))
        if not len(idx):
            return []
        due = np.zeros(len(self.plugins), bool)
        due[idx] = True
        plugins = self.plugins
        positions: list[np.ndarray] = []
        ordered: list[Any] = []
        batched: list[tuple[int, list, list]] = []
        singles = self.singles[due[self.singles]]
        if len(singles):
            positions.append(singles)
            for i in singles.tolist():
                r = plugins[i].measure(engine, t)
                if r is not None:
                    r.namespace = plugins[i].ctx.namespace
                ordered.append(r)
        for cls, kind, ids in self.groups:
            sel = ids[due[ids]]
            if not len(sel):
                continue
            group = [plugins[i] for i in sel.tolist()]
            if kind == EACH:
                positions.append(sel)
                ordered += cls.measure_each(engine, group, t)
            else:
                batched.append((int(sel[0]), cls.measure_batch(engine, group, t), group))
        if len(positions) > 1:
            order = np.argsort(np.concatenate(positions), kind="stable").tolist()
            ordered = [ordered[k] for k in order]
        out = [r for r in ordered if r is not None]
        for _, readings, group in sorted(batched, key=lambda b: b[0]):
            for r, p in zip(readings, group):
                r.namespace = p.ctx.namespace
                out.append(r)
        # lasers nobody listens to cast nothing (their due times still advance, as an inactive
        # Gazebo sensor's update clock does)
        due_lasers = self.lasers[due[self.lasers]].tolist()
        group = [plugins[i] for i in due_lasers if _wanted(plugins[i])]
        if group:
            for r, p in zip(engine.lasers.measure(engine, group, t), group):
                r.namespace = p.ctx.namespace
                out.append(r)
        return out


def _wanted(plugin: Any) -> bool:
    """Whether a sensor's output has a reader (``plugin.wanted``: None means always)."""
    wanted = getattr(plugin, "wanted", None)
    return wanted is None or wanted()
