"""Giving way at a crossing: the rule above ORCA for two robots carried along side by side.

Two robots whose ways cross while they move the same general way (their lanes must swap: each
one's goal lies on the other's side) meet beside each other, and ORCA keeps them there: the
velocity nearest each one's preference is to run on alongside the other (passing behind it
would first mean going backwards, which no velocity near the preference does), so the pair
drifts off both ways together until one of them stops. On the circle of 16 (held-out seed 9)
lizi10 was carried 2 m off its plan this way by lizi2, whose goal is next to its own, ended on
the far side of lizi2 parked on its goal, went round it and turned 2.3 rad on the spot there:
its last 2.3 m took 11 s against 4.6 s alone.

The rule: a robot is *carried* by a navigating neighbour that moves our way (its velocity
has a positive component along ours), sits across our preferred way (the ray along the
preferred velocity, before keeping right, enters its ORCA disc within `REACH`) while our own
motion does not run into it (the ray along our velocity is clear of it: it is beside us, not a
leader we follow), and our velocity is more than 60 deg off our preferred way
(`CARRIED_OFF`). Only outside a meeting (the robots that carry us do not count in it: a carrier
drifting into us closes in, but does not come against us): while robots come against us, keeping
right (``left_pref``) deliberately sets the crowd flowing round side by side, and dropping back
there jammed the circle of 16 (tuning seeds 0-4: makespan 16.4 / 17.8 s mean / max without the
rule, 22.1 / 24.2 s standing in every crossing, 20.1 / 22.2 s dropping back). After
`CROSSING_TIME` s of being carried by the same robot, the robot of the two with the lower priority
(`fleetsim.nav.multirobot.deadlock.priority_key`, the deadlock rule's order: every robot
reaches the same verdict) *gives way*, until the other robot is no longer in its way (across
its preferred way, and met within ``time_horizon`` going that way: `collision_course`) or has
stopped navigating (parked on its goal: a robot standing in the way is gone round), or at most
`GIVE_WAY_TIME` s. A robot crossing our way at crowd speed is out of it before its disc has
left the ray along our way: waiting for the ray, a lizi already turned to its way stood ~1 s
longer (circle of 16, seeds 10-29: every makespan over 17.5 s was a robot giving way from ~9 s
on, for 2-3.5 s; 17.12 / 18.7 s mean / max -> 16.63 / 17.7 s with `collision_course`).
A differential drive gives way by *standing and turning on the
spot towards its way* (where `room_to_turn`): a base that cannot move sideways, dropping back
beside the other, is dragged along by it (the other's way to its goal runs through us, and a
velocity off our heading means driving with it), while a robot standing still is one the other
goes round, with all the responsibility (``_around_still``), and once the other is past, the
robot already faces its way. Its forward speed is only what the half-planes require along its
heading, as a robot waiting in its refuge (`fleetsim.nav.multirobot.holonomic.speed_nearest_still`).
A robot with another one within its turn's reach (nearer than their combined radius and
`TURN_CLEARANCE`: a follower close behind) drops back to `GIVE_WAY_SPEED` of its preferred
speed instead, taking all the responsibility for the other (standing there, a follower ran into
its turning corner). Circle of 16, seed 11 (beyond the tuning seeds): lizi10, carried by lizi2,
21.3 s dropping back, 18.9 s turning on the spot; seeds 0-4 and 10, 12-19 unchanged.
"""

from __future__ import annotations

import numpy as np

from fleetsim.nav.multirobot.deadlock import priority_key

#: s a robot is carried by the same neighbour before the one with the lower priority gives way
#: (the narrow meeting's 1 s: short, the pair drifts off at full speed meanwhile)
CROSSING_TIME = 1.0
#: s at most a robot gives way (the other robot has crossed its way within ~2 s at crowd speed)
GIVE_WAY_TIME = 4.0
#: share of its preferred speed a robot giving way keeps (standing, it stopped the robots behind
#: it too)
GIVE_WAY_SPEED = 0.5
#: m added to a pair's combined radius within which another robot keeps a robot that gives way
#: from turning on the spot (a lizi's corners sweep its circumscribed disc; a follower 0.45 m
#: behind was touched)
TURN_CLEARANCE = 0.15
#: m/s: below this our own velocity has no direction (a robot standing is not carried)
MOVING = 0.05
#: cosine of the angle between our velocity and our preferred way above which we are not
#: carried off (60 deg: at least half our speed still goes where we want to; lizi10 in seed 9
#: was held ~70 deg off its way)
CARRIED_OFF = 0.5
#: m along the preferred way within which a neighbour is across it: as far as a robot standing
#: in the way is gone round (`fleetsim.nav.controllers.collvoid_preference.DETOUR_REACH`)
REACH = 1.0
#: s the robot given way to may stand against us (their discs touching) before the give-way
#: ends: it is not getting past, and standing there we hold it up. On the circle of 16 (seed 12)
#: lizi14 gave way standing on lizi7's goal, and lizi7, which must not close in on a body
#: (`fleetsim.nav.multirobot.orca.contact_halfplanes`), waited beside it for the whole
#: `GIVE_WAY_TIME`
AGAINST_TIME = 1.0


def across_way(rel_pos: np.ndarray, radii: np.ndarray, direction: np.ndarray, reach: float):
    """(N,) bool: whether the ray from the robot (at the origin) along ``direction`` (2,) enters
    each disc (``rel_pos`` (N, 2) m, combined ``radii`` (N,) m) within ``reach`` m (per disc,
    where `fleetsim.nav.multirobot.holonomic.rays_blocked` answers for all discs at once)."""
    n = float(np.hypot(*direction))
    if n < 1e-9 or rel_pos.shape[0] == 0:
        return np.zeros(rel_pos.shape[0], dtype=bool)
    u = np.asarray(direction, dtype=np.float64) / n
    along = rel_pos @ u
    inside, entry = _ray_entry(along, u[0] * rel_pos[:, 1] - u[1] * rel_pos[:, 0], radii)
    return (along > 1e-9) & (inside > 0.0) & (entry < reach)


def _ray_entry(along: np.ndarray, side: np.ndarray, radii: np.ndarray) -> tuple:
    """For rays meeting discs of ``radii`` (N,) m whose centres lie ``along`` (N,) m along and
    ``side`` (N,) m across them: (radius^2 - side^2, > 0 where the ray's line crosses the
    disc; m along the ray where it enters the disc)."""
    inside = radii**2 - side**2
    return inside, along - np.sqrt(np.maximum(inside, 0.0))


def collision_course(
    velocity: np.ndarray,
    rel_pos: np.ndarray,
    velocities: np.ndarray,
    radii: np.ndarray,
    horizon: float,
) -> np.ndarray:
    """(N,) bool: whether the robot (at the origin) moving at ``velocity`` (2,) m/s meets each
    neighbour (``rel_pos`` (N, 2) m, moving at ``velocities`` (N, 2) m/s, combined ``radii``
    (N,) m) within ``horizon`` s: the relative velocity inside the pair's velocity obstacle
    (its cone cut at the horizon, as ORCA's)."""
    w = np.asarray(velocity, dtype=np.float64)[None, :] - velocities
    speed = np.hypot(w[:, 0], w[:, 1])
    u = w / np.maximum(speed, 1e-9)[:, None]
    along = np.einsum("ij,ij->i", u, rel_pos)
    inside, entry = _ray_entry(along, u[:, 0] * rel_pos[:, 1] - u[:, 1] * rel_pos[:, 0], radii)
    inside_now = np.hypot(rel_pos[:, 0], rel_pos[:, 1]) < radii
    hit = (speed > 1e-9) & (along > 0.0) & (inside > 0.0) & (entry < speed * horizon)
    return hit | (inside_now & (along > 0.0))


def carried_by(
    rel_pos: np.ndarray,
    velocities: np.ndarray,
    radii: np.ndarray,
    velocity: np.ndarray,
    pref: np.ndarray,
    reach: float,
) -> np.ndarray:
    """(N,) bool: the neighbours that carry the robot (at the origin) off its preferred way.

    rel_pos : (N, 2) m, the neighbours relative to the robot; velocities : (N, 2) m/s, theirs;
    radii : (N,) m, combined (ours + theirs, as ORCA's); velocity : (2,) m/s, ours;
    pref : (2,) m/s, our preferred velocity; reach : m, how far along the preferred way a
    neighbour counts as across it. A neighbour carries us when it moves our way
    (``velocities @ velocity > 0``), the ray along ``pref`` enters its disc within ``reach``
    and the ray along ``velocity`` does not (see the module doc).
    """
    n = rel_pos.shape[0]
    speed, pref_speed = float(np.hypot(*velocity)), float(np.hypot(*pref))
    if n == 0 or speed < MOVING or pref_speed < 1e-9:
        return np.zeros(n, dtype=bool)
    if float(np.dot(velocity, pref)) > CARRIED_OFF * speed * pref_speed:
        return np.zeros(n, dtype=bool)
    along = velocities @ np.asarray(velocity, dtype=np.float64) > 0.0
    wanted = across_way(rel_pos, radii, pref, reach)
    return along & wanted & ~across_way(rel_pos, radii, velocity, reach)


class GiveWay:
    """One robot's state of the crossing rule (see the module doc)."""

    def __init__(self, robot_id: str) -> None:
        self.robot_id = robot_id
        self.reset()

    def reset(self) -> None:
        """A new goal: no crossing under way."""
        self.to: str | None = None  # the robot given way to
        self.until = -np.inf
        self.since: dict[str, float] = {}  # neighbour -> since when it carries us
        self.against_since: float | None = None  # since when the robot given way to touches us
        self.not_before: dict[str, float] = {}  # neighbour -> no give-way to it before then

    def update(
        self,
        now: float,
        ids: list[str],
        carrying: np.ndarray,
        in_the_way: np.ndarray,
        navigating: np.ndarray,
        against: np.ndarray | None = None,
    ) -> str | None:
        """The robot to give way to this cycle, or None.

        ids : the neighbours' ids (N,); carrying : (N,) bool, `carried_by`;
        in_the_way : (N,) bool, each one still in our way (the ray along our preferred way
        enters its disc within reach, and our preferred velocity meets it within the time
        horizon, `collision_course`); navigating : (N,) bool, each one still on its way
        (``controlled``: a robot that slows down or stops for a moment beside a robot giving
        way is still to be let by; ending there, both robots stood and then drove on side by
        side again); against : (N,) bool, each one's disc touching ours (`AGAINST_TIME`: the
        give-way ends, and the robot is not given way to again within `GIVE_WAY_TIME`).
        """
        if self.to is not None:
            k = ids.index(self.to) if self.to in ids else -1
            if k >= 0 and against is not None and against[k]:
                if self.against_since is None:
                    self.against_since = now
            else:
                self.against_since = None
            held = self.against_since is not None and now - self.against_since >= AGAINST_TIME
            if k >= 0 and now < self.until and in_the_way[k] and navigating[k] and not held:
                return self.to
            if held:
                self.not_before[self.to] = now + GIVE_WAY_TIME
            self.to = None
            self.against_since = None
            self.since.clear()
        now_carrying = {ids[k] for k in np.flatnonzero(carrying)}
        self.since = {i: self.since.get(i, now) for i in now_carrying}
        mine = priority_key(self.robot_id)
        due = [
            i
            for i, t in self.since.items()
            if now - t >= CROSSING_TIME
            and priority_key(i) < mine
            and now >= self.not_before.get(i, -np.inf)
        ]
        if not due:
            return None
        self.to = min(due, key=priority_key)
        self.until = now + GIVE_WAY_TIME
        return self.to


def room_to_turn(rel_pos: np.ndarray, radii: np.ndarray, other: int) -> bool:
    """Whether a robot (at the origin) giving way to neighbour ``other`` may stand and turn on
    the spot: no neighbour but that one nearer than their combined radius (``radii`` (N,) m,
    ``rel_pos`` (N, 2) m) and `TURN_CLEARANCE`."""
    near = np.hypot(rel_pos[:, 0], rel_pos[:, 1]) < radii + TURN_CLEARANCE
    near[other] = False
    return not bool(near.any())
