"""The sensor schedule: due times (against the one-plugin-at-a-time rule) and reading order."""

from types import SimpleNamespace

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim.plugins.base import Plugin
from fleetsim.sim.schedule import SensorSchedule, _advanced, due_times_advanced


def due_time_reference(due: float, period: float, t: float) -> tuple[bool, float]:
    """The rule for one plugin, as the engine applied it plugin by plugin."""
    if t + 1e-9 < due:
        return False, due
    nxt = due + period if due > 0 else t + period
    if nxt <= t + 1e-9:
        nxt = t + period
    return True, nxt


@settings(max_examples=80, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from([0.0, 0.004, 0.01, 0.02, 0.05, 0.1, 1 / 3]),
            st.floats(0.0, 2.0),
        ),
        min_size=1,
        max_size=20,
    ),
    st.floats(0.0, 2.0),
)
def test_due_times_follow_the_one_plugin_rule(plugins, t):
    period = np.array([p for p, _ in plugins])
    due_at = np.array([d for _, d in plugins])
    want = [due_time_reference(d, p, t) for p, d in plugins]
    idx = due_times_advanced(due_at, period, t)
    assert idx.tolist() == [i for i, (due, _) in enumerate(want) if due]
    assert due_at.tolist() == [nxt for _, nxt in want]  # bit-identical
    again = due_at.copy()
    idx, earliest = _advanced(again, period, t)  # what the schedule calls: also the next due
    assert earliest == min(again.tolist())


class Named(Plugin):
    """A sensing plugin that reports its own name (measured one by one)."""

    def __init__(self, name: str, rate: float) -> None:
        self.name, self.rate = name, rate
        self.ctx = SimpleNamespace(namespace=f"/{name}")

    @property
    def update_rate(self) -> float:
        return self.rate

    def measure(self, engine, t):
        engine.log.append(self.name)
        return SimpleNamespace(name=self.name, stamp=t, namespace=None)


class Each(Named):
    @classmethod
    def measure_each(cls, engine, plugins, t):
        engine.log.append(tuple(p.name for p in plugins))
        return [SimpleNamespace(name=p.name, stamp=t, namespace=p.ctx.namespace) for p in plugins]


class Batch(Named):
    @classmethod
    def measure_batch(cls, engine, plugins, t):
        return [SimpleNamespace(name=p.name, stamp=t, namespace=None) for p in plugins]


class Laser(Named):
    is_laser = True


class Silent(Plugin):
    """No readings: left out of the schedule."""


def test_reading_order_and_rates():
    lasers = SimpleNamespace(
        measure=lambda engine, group, t: [
            SimpleNamespace(name=p.name, stamp=t, namespace=None) for p in group
        ]
    )
    engine = SimpleNamespace(lasers=lasers, log=[])
    plugins = [
        Batch("b1", 10.0),
        Laser("l1", 5.0),
        Named("n1", 10.0),
        Each("e1", 10.0),
        Silent.__new__(Silent),
        Named("n2", 5.0),
        Each("e2", 5.0),
        Batch("b2", 5.0),
    ]
    s = SensorSchedule()
    s.bind(plugins)
    assert len(s.plugins) == 7
    first = s.readings(engine, 0.0)
    assert [r.name for r in first] == ["n1", "e1", "n2", "e2", "b1", "b2", "l1"]
    assert [r.namespace for r in first] == ["/n1", "/e1", "/n2", "/e2", "/b1", "/b2", "/l1"]
    assert engine.log == ["n1", "n2", ("e1", "e2")]
    assert s.next == 0.1
    assert s.readings(engine, 0.05) == []
    assert [r.name for r in s.readings(engine, 0.1)] == ["n1", "e1", "b1"]
    assert [r.name for r in s.readings(engine, 0.2)] == ["n1", "e1", "n2", "e2", "b1", "b2", "l1"]
    # a rebind keeps the due times of the plugins that stay; new ones fall due at once
    s.bind([*plugins[:3], Named("n3", 10.0)])
    assert [r.name for r in s.readings(engine, 0.25)] == ["n3"]
    s.restart()
    assert [r.name for r in s.readings(engine, 0.25)] == ["n1", "n3", "b1", "l1"]
