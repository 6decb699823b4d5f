"""The rule above ORCA that ends deadlocks: no-progress detection, then a priority decision that
every robot computes the same way.

ORCA alone stops in symmetric meetings and in passages too narrow for two (the reference
measurement with RVO2: exact head-on pairs and 0.6 m corridors never finish). Each robot runs a
`DeadlockRule`:

1. progress is the remaining distance to the goal; when it has not shrunk by
   ``deadlock_progress`` m for ``deadlock_time`` s while another robot is within
   ``deadlock_radius`` m, the robot is *stuck*; when a robot faces it across a passage too
   narrow for two (the planner measures it: a *narrow meeting*) after ``narrow_time`` s of
   that meeting already, progress or not: no reciprocal method resolves it (ORCA only slows
   the pair to a creep), waiting longer only loses time; when a robot faces it head-on (ahead,
   facing it, not drawing away) and it has not made ``deadlock_progress`` m for
   ``standoff_time`` s, it is in a *standoff* with that robot: the passage is wide enough by the
   walls, but robots beside the two fill it (two pairs abreast in a corridor meet front to
   front and creep at a few cm/s; the no-progress clock alone waits ``deadlock_time`` for
   that), and it yields only to a robot it faces: of several, the one with the highest
   priority (four jackals in two lanes, a head-on pair in each: jackal4 yielding to jackal3,
   the nearer, diagonally across and blocked itself, freed nobody; jackal1, in jackal4's own
   lane, is the highest-priority robot met);
2. a stuck robot looks at the robots around it that are navigating (``controlled`` on
   /position_share; a robot parked at its goal will not move, waiting for it is pointless):
   priority goes by robot id (natural order, so ``lizi2`` before ``lizi10``); every robot sees
   the same ids, so all reach the same verdict without talking. If one of them has priority
   over it, it *yields* to the nearest such robot (in a standoff, the one with the highest
   priority among those it faces; see 1): it takes full responsibility for avoiding
   it (the priority robot keeps its half and drives on), retreats along its own plan to a place
   wide enough for both and waits there, aside, until that robot has gone by or is out of
   its way (`fleetsim.nav.multirobot.yielding`; the planner calls `release`), or at most
   ``yield_time`` s;
3. after yielding, the progress clock restarts, so a robot that is still stuck yields again.

The robot with the highest priority among those stuck never yields, so a group always has one
robot that keeps going.
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass
from typing import Any


def priority_key(robot_id: str) -> tuple:
    """Natural sort key: lower sorts first and has priority (``lizi2`` < ``lizi10``)."""
    return tuple(int(t) if t.isdigit() else t for t in re.split(r"(\d+)", robot_id))


@dataclass
class DeadlockRule:
    """One robot's deadlock state (see the module doc).

    The times and distances have no defaults here: they are the local planner's parameters
    (``deadlock_time``, ``deadlock_progress``, ``deadlock_radius``, ``yield_time``,
    ``narrow_deadlock_time`` of `fleetsim.nav.controllers.collvoid_params.CollvoidParams`),
    declared there once; `from_params` takes them from such a parameter set.
    """

    robot_id: str
    deadlock_time: float
    deadlock_progress: float
    deadlock_radius: float
    yield_time: float
    narrow_time: float
    standoff_time: float

    def __post_init__(self) -> None:
        self.reset(0.0)

    @classmethod
    def from_params(cls, robot_id: str, params: Any) -> DeadlockRule:
        """The rule with a planner parameter set's deadlock fields (any object with them)."""
        return cls(
            robot_id,
            params.deadlock_time,
            params.deadlock_progress,
            params.deadlock_radius,
            params.yield_time,
            params.narrow_deadlock_time,
            params.standoff_time,
        )

    def reset(self, now: float, remaining: float = float("inf")) -> None:
        """A new goal: forget progress and any yielding."""
        self.best = remaining
        self.best_time = now
        self.yield_to: str | None = None
        self.yield_until = -float("inf")
        self.yields = 0
        self.narrow_since: float | None = None

    def release(self, now: float, remaining: float) -> None:
        """The robot yielded to has gone by or is out of the way: the yield ends, the progress
        clock restarts."""
        self.yield_to = None
        self.yield_until = -float("inf")
        self.best, self.best_time = remaining, now
        self.narrow_since = None

    def update(
        self,
        now: float,
        remaining: float,
        nearby: dict[str, float],
        narrow: Collection[str] = (),
        facing: Collection[str] = (),
    ) -> str | None:
        """The robot to yield to this cycle, or None.

        remaining : m to the goal; nearby : robot id -> distance (m) of the navigating robots
        around; narrow : the robots of a narrow meeting (each faces this one across a passage
        too narrow for two; they take part at any distance, not only within deadlock_radius);
        facing : the robots that face this one head-on, ahead of it and not drawing away (a
        standoff with one of them after ``standoff_time`` s without progress).
        """
        if remaining < self.best - self.deadlock_progress:
            self.best, self.best_time = remaining, now
        if not narrow:
            self.narrow_since = None
        elif self.narrow_since is None:
            self.narrow_since = now
        if self.yield_to is not None:
            if now < self.yield_until and self.yield_to in nearby:
                return self.yield_to
            self.yield_to = None
            self.best, self.best_time = remaining, now
            self.narrow_since = now if narrow else None
        close = {k: d for k, d in nearby.items() if d <= self.deadlock_radius or k in narrow}
        waited = now - self.best_time
        patience = self.deadlock_time
        if self.narrow_since is not None:
            waited = max(waited, now - self.narrow_since)
            patience = min(self.narrow_time, self.deadlock_time)
        if not close:
            return None
        standoff = False
        if waited < patience:
            if waited < self.standoff_time:
                return None
            # a standoff: only the robots met head-on take part, and keeping the right of way
            # there restarts no clock (the no-progress rule still runs for the others around)
            close = {k: d for k, d in close.items() if k in facing}
            standoff = True
        mine = priority_key(self.robot_id)
        higher = [k for k in close if priority_key(k) < mine]
        if standoff and not higher:
            return None
        if not higher:
            self.best, self.best_time = remaining, now  # we keep the right of way
            self.narrow_since = now if narrow else None
            return None
        if standoff:  # met head-on by several: the highest-priority robot met
            self.yield_to = min(higher, key=priority_key)
        else:
            self.yield_to = min(higher, key=lambda k: close[k])
        self.yield_until = now + self.yield_time
        self.yields += 1
        return self.yield_to
