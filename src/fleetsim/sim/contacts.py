"""Contact rules that keep wheeled robots on the floor: floor contacts as explicit pairs with a
soft friction reference, and drive wheels without friction against anything but a floor.

Why. MuJoCo's contact model is convex (Todorov 2014), so it cannot be exactly Coulomb: while a
contact slides at speed ``v`` the solver pushes the two surfaces apart, at an acceleration of
about ``mu * b * v`` where ``b = 2 / (dmax * timeconst)`` is the reference damping of the
friction rows (``solref``). With the default 0.02 s (``b`` ~ 105 /s) a 7 kg box sliding at
5 m/s over a plane leaves it at 1 m/s (5 cm up; at 1 m/s 2 mm); a robot held by a wall with its
wheels spinning at top speed hopped again and again (lizi 6 cm, jackal 12, pioneer3at 17), and
in the 10-lizi soak two lizis were thrown up at ~5 m/s from a pile-up. A stiffer contact
(smaller ``timeconst``) makes it worse, a smaller physics step better only in proportion (and
costs as much). Two rules:

- **Floor contacts**: every movable collision geom touches every floor plane through an explicit
  ``<pair>`` (MuJoCo then skips the pair in its dynamic collision pass) whose friction directions
  have their own reference time constant, `FLOOR_FRICTION_TIMECONST` (0.15 s: ``b`` 7.5x smaller,
  and the push apart with it). Robots held by a wall with their wheels at top speed now lift no
  wheel more than 1.5 cm off the floor (pioneer3at; lizi and jackal < 5 mm). Friction is still
  bounded by ``mu`` times the normal force (a 5 m/s box stops within 1 % of the Coulomb distance
  ``v^2 / (2 mu g)``); the gentler reference lets a slip last a little longer before friction
  holds (at 1 m/s the box slides ~1 cm further). Measured alternatives: 0.1 s leaves hops of 1-7
  cm; 0.2 s changes how the turtlebots turn enough for the building-patrol follower to lose its
  marker; a stiffer normal (0.01 s) cuts the push apart further, but robots spawned into the floor
  (z = 0 with the root at axle height) then pop up to 0.9 m instead of 6-14 cm. Friction,
  ``condim`` (3), ``solref`` and ``solimp`` are the movable geom's, as the dynamic contact took
  them (movable geoms have the higher priority, ``sim.build``).
- **Drive wheels** (`frictionless_wheels`, called by the wheeled drive plugins): their geoms get
  ``condim = 1`` and a priority above every other geom, so against walls, other robots and
  objects they push without friction. A wheel spinning at full speed against another robot's
  wheel or body otherwise climbed it as a tread would (lizis pushing into each other at 0.5 m/s
  ended stacked 15 cm high). Their traction comes from the floor pairs, which carry the
  wheel's own ``mu``.

Floors are the plane geoms (the ground plane of SDF and map worlds). A robot on a box or mesh
"floor" keeps MuJoCo's ordinary contact there, and its drive wheels have no traction on it.
"""

from __future__ import annotations

import mujoco

#: s, reference time constant of the friction directions of floor contacts (MuJoCo's default
#: contact time constant is 0.02 s; see the module docstring)
FLOOR_FRICTION_TIMECONST = 0.15
#: geom priority of drive wheels: above movable (1) and static (0) geoms, so that a wheel's
#: ``condim = 1`` decides its contacts with them
WHEEL_PRIORITY = 2
_PAIR_PREFIX = "floor:"


def _collides(g) -> bool:
    return bool(g.contype or g.conaffinity)


def _movable(g) -> bool:
    # sim.build: static geoms are (contype 2, conaffinity 1), movable ones (1, 3)
    return _collides(g) and bool(g.contype & 1) and g.type != mujoco.mjtGeom.mjGEOM_PLANE


def sync_floor_pairs(spec: mujoco.MjSpec) -> int:
    """Make the spec's floor pairs match its geoms: one per (floor plane, movable collision
    geom), named ``floor:<plane>|<geom>``; pairs of deleted geoms are removed. Call before
    every compile. Returns the number of floor pairs.
    """
    geoms = [g for g in spec.geoms if g.name]
    planes = [g for g in geoms if g.type == mujoco.mjtGeom.mjGEOM_PLANE and _collides(g)]
    movers = [g for g in geoms if _movable(g)]
    wanted = {f"{_PAIR_PREFIX}{p.name}|{g.name}": (p, g) for p in planes for g in movers}
    have = {}
    for pair in list(spec.pairs):
        if pair.name.startswith(_PAIR_PREFIX):
            if pair.name in wanted:
                have[pair.name] = pair
            else:
                spec.delete(pair)
    for name, (plane, g) in wanted.items():
        if name not in have:
            _add_floor_pair(spec, name, plane, g)
    return len(wanted)


def _add_floor_pair(spec: mujoco.MjSpec, name: str, plane, g) -> None:
    slide, spin, roll = (float(v) for v in g.friction)
    spec.add_pair(
        name=name,
        geomname1=plane.name,
        geomname2=g.name,
        condim=3,
        friction=[slide, slide, spin, roll, roll],
        solref=list(g.solref),
        solimp=list(g.solimp),
        solreffriction=[FLOOR_FRICTION_TIMECONST, 1.0],
        margin=max(float(g.margin), float(plane.margin)),
        gap=max(float(g.gap), float(plane.gap)),
    )


def frictionless_wheels(bodies: list) -> None:
    """Make the collision geoms of the wheel ``bodies`` (``MjSpec`` bodies) touch anything but
    a floor without friction: ``condim = 1`` and `WHEEL_PRIORITY`, so the wheel's ``condim``
    wins the mixing. Their friction stays on the geom, where the floor pairs read it."""
    for body in bodies:
        for g in body.geoms:
            if _collides(g):
                g.condim = 1
                g.priority = WHEEL_PRIORITY
