"""Where an exploration run's time goes (slam_quality.py ``--trace``): each explorer's goals,
how each goal ended, and every sim second what each robot was doing.

Every goal explore sends is logged with the frontier it picked (size, distance, how many
frontiers there were, the peer's goal); a goal ends reached, aborted, replaced by another
frontier (``switched`` while its frontier is still there, ``closed`` when the frontier it headed
for had gone from the explorer's map), or blacklisted for want of progress. Every sim second
each robot is ``driving`` to a frontier that is still open, ``stale`` (driving to a goal whose
frontier is gone from the map it explores), ``idle`` (no goal, not finished) or ``finished``;
the map's own frontiers (the merged map's, or the one robot's) are found from each robot's
position, so the summary says when the map had none left against when the run ended.
"""

from __future__ import annotations

import contextlib
import math
from collections import defaultdict

import numpy as np

STALE_RADIUS = 1.0  # m: a goal with no frontier centroid this near has lost its frontier


def _near(goal, frontiers, radius: float = STALE_RADIUS) -> bool:
    return any(math.dist(goal, f.goal) < radius for f in frontiers)


class ExploreTrace:
    """Patches `Explore` while active; ``sample`` once a sim second; ``summary`` at the end."""

    def __init__(self) -> None:
        self.events: dict[str, list] = defaultdict(list)
        self.states: dict[str, list[str]] = defaultdict(list)
        self.paths: dict[str, list] = defaultdict(list)
        self.open_until: float | None = None  # last sample the map still had a frontier
        self.t = 0.0

    @contextlib.contextmanager
    def patch(self):
        from fleetsim.nav.explore import Explore

        trace = self
        send, done = Explore._send, Explore._on_done

        def traced_send(ex, target, frame, yaw=0.0):
            old = ex.goal if ex._handle is not None else None
            if old is not None:
                how = "switched" if _near(old, ex.frontiers) else "closed"
                trace._end(ex, old, how)
            f = next((f for f in ex.frontiers if math.dist(f.goal, target) < 1e-6), None)
            peers = [g for g in ex.peers.values() if g is not None]
            at = trace.paths[ex.namespace][-1] if trace.paths[ex.namespace] else (math.nan,) * 2
            trace.events[ex.namespace].append(
                dict(t=ex.now(), kind="send", goal=target, size=f.size if f else 0,
                     distance=f.min_distance if f else math.nan, frontiers=len(ex.frontiers),
                     peer_goal=peers[0] if peers else None, at=at)
            )  # fmt: skip
            return send(ex, target, frame, yaw)

        def traced_done(ex, goal, status):
            if ex.goal == goal:
                trace._end(ex, goal, {3: "reached", 4: "aborted"}.get(status, f"status {status}"))
            return done(ex, goal, status)

        Explore._send, Explore._on_done = traced_send, traced_done
        try:
            yield self
        finally:
            Explore._send, Explore._on_done = send, done

    def _end(self, ex, goal, how: str) -> None:
        self.events[ex.namespace].append(dict(t=ex.now(), kind=how, goal=goal))

    def sample(self, t: float, explorers, positions, grid) -> None:
        """One sim second: ``explorers`` by namespace, ``positions`` their true (x, y),
        ``grid`` the OccupancyGrid they explore (merged map or the robot's own)."""
        from fleetsim.nav.explore import frontiers_from_grid

        self.t = t
        for (ns, ex), pos in zip(explorers.items(), positions):
            self.paths[ns].append(pos)
            bl = self.events[ns]
            if len(ex.blacklist) > sum(e["kind"] in ("blacklisted", "aborted") for e in bl):
                self._end(ex, ex.blacklist[-1], "blacklisted")
            if ex.finished:
                state = "finished"
            elif ex.goal is None:
                state = "idle"
            else:
                state = "driving" if _near(ex.goal, ex.frontiers) else "stale"
            self.states[ns].append(state)
        if grid is None:
            return
        info = grid.info
        data = np.asarray(grid.data, dtype=np.int8).reshape(info.height, info.width)
        origin = (info.origin.position.x, info.origin.position.y)
        if any(frontiers_from_grid(data, info.resolution, origin, p) for p in positions):
            self.open_until = t

    def summary(self, log: bool = True) -> None:
        """Print the goal log (``log``) and the per-robot time budget."""
        for ns, events in self.events.items():
            name = ns.strip("/") or "robot"
            if log:
                for e in events:
                    gx, gy = e["goal"]
                    line = f"    {e['t']:6.0f} s {name:8s} {e['kind']:11s} ({gx:5.1f}, {gy:5.1f})"
                    if e["kind"] == "send":
                        peer = e["peer_goal"]
                        line += (f" from ({e['at'][0]:.1f}, {e['at'][1]:.1f})"
                                 f" size {e['size']:3d} at {e['distance']:4.1f} m of "
                                 f"{e['frontiers']} frontiers")  # fmt: skip
                        if peer:
                            line += f", peer -> ({peer[0]:.1f}, {peer[1]:.1f})"
                    print(line)
            states = self.states[ns]
            count = {k: states.count(k) for k in ("driving", "stale", "idle", "finished")}
            kinds = [e["kind"] for e in events]
            ends = {k: kinds.count(k) for k in sorted(set(kinds)) if k != "send"}
            path = np.array(self.paths[ns])
            length = float(np.hypot(*np.diff(path, axis=0).T).sum()) if len(path) > 1 else 0.0
            blacklisted_time = self._time_on(events, "blacklisted")
            print(
                f"  {name}: {kinds.count('send')} goals {ends}; sim s driving {count['driving']},"
                f" stale goal {count['stale']}, idle {count['idle']}, finished {count['finished']}"
                f"; {blacklisted_time:.0f} s towards goals later blacklisted; path {length:.0f} m"
            )
        if self.open_until is not None:
            print(f"  the map's last frontier closed at {self.open_until + 1:.0f} s; run ended "
                  f"{self.t:.0f} s")  # fmt: skip

    @staticmethod
    def _time_on(events, kind: str) -> float:
        """Sim s from sending each goal to its end, for the goals whose end was ``kind``."""
        total, sent = 0.0, {}
        for e in events:
            if e["kind"] == "send":
                sent[e["goal"]] = e["t"]
            elif e["kind"] == kind and e["goal"] in sent:
                total += e["t"] - sent[e["goal"]]
        return total
