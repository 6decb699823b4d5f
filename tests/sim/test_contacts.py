"""Contacts that do not throw robots into the air (``sim.contacts``).

MuJoCo's convex soft contacts push two surfaces apart while they slide, at a rate that grows
with the slip speed: a drive wheel spinning on the floor, with its robot blocked, made the robot
hop; in pile-ups the hops, and treads climbing other robots' wheels, threw robots up (the
10-lizi soak: two lizis at ~5 m/s). Every shipped robot, spawned on the floor, settled, then
driven into a wall and into three others, stays within a few centimetres of the floor.
Each test runs in a temporary directory, where a ``MUJOCO_LOG.TXT`` would show up.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fleetsim.description import load_robot
from fleetsim.sim import Engine
from fleetsim.sim.contacts import FLOOR_FRICTION_TIMECONST
from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc, WorldDesc, ground_plane

from .test_physics_health import drive_of, top_speed

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
FILES = sorted(ROBOTS.glob("*/urdf/*.urdf.xacro"))
IDS = [p.parts[-3] for p in FILES]
SETTLE = 1.5  # s on the floor before the drives start (robots are spawned at z = 0)


def settle(e: Engine) -> None:
    """Physics only (``advance`` would render the robots' cameras)."""
    for _ in range(round(SETTLE / e.model.opt.timestep)):
        e.step()


pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def wall_world(x: float) -> WorldDesc:
    wall = ModelDesc(
        "wall", (x, 0, 0.5, 0, 0, 0), True, [LinkDesc("l", geoms=[GeomDesc("box", (0.1, 6, 1))])]
    )
    return WorldDesc("w", [ground_plane(), wall])


def clearance(e: Engine, floor: int, geoms: np.ndarray) -> float:
    """Distance (m) from the floor to the lowest of ``geoms`` (one robot's collision geoms):
    0 while any part of the robot touches the floor, whether it stands or lies on its side."""
    return min(mujoco.mj_geomDistance(e.model, e.data, floor, int(g), 1.0, None) for g in geoms)


def highest_lift(e: Engine, names: list[str], steps: int, command) -> float:
    """Step ``steps`` physics steps calling ``command()`` every 5; the largest `clearance` (m)
    any named robot reached. No MuJoCo warning may trip."""
    m = e.model
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground_plane/link/collision#0")
    collide = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    robots = [np.flatnonzero(collide & (e.geom_model == list(e.models).index(n))) for n in names]
    most = 0.0
    for k in range(steps):
        if k % 5 == 0:
            command()
        e.step()
        assert not e.data.warning.number.any()
        if k % 2 == 0:
            mujoco.mj_kinematics(m, e.data)
            most = max(most, *(clearance(e, floor, geoms) for geoms in robots))
    return most


def pile_up(path: Path, speed: float, seconds: float, seed: int) -> float:
    """Four robots on a half circle, driven at ``speed`` (at most their top speed) with a slow
    weave towards one point near a wall; returns the highest any of them was lifted off the
    floor (m, `highest_lift`)."""
    e = Engine(wall_world(1.5))
    robot = load_robot(path)
    rng = np.random.default_rng(seed)
    poses = []
    for i in range(4):
        a = math.pi / 2 + math.pi * (i + 0.5) / 4
        x, y = 0.9 + 1.2 * math.cos(a), 1.2 * math.sin(a)
        poses.append((x, y, 0, 0, 0, math.atan2(-y, 1.3 - x) + rng.uniform(-0.2, 0.2)))
    entries = e.spawn_robots([(f"r{i}", robot, p) for i, p in enumerate(poses)])
    drives = [drive_of(en) for en in entries]
    v = min(speed, top_speed(entries[0], drives[0]))
    settle(e)

    def command() -> None:
        for i, d in enumerate(drives):
            d.command(v, 0.3 * math.sin(3 * e.time + i), e.time)

    steps = round(seconds / e.model.opt.timestep)
    return highest_lift(e, [en.name for en in entries], steps, command)


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_blocked_robot_spinning_its_wheels_stays_on_the_floor(path):
    """A robot held by a wall with its wheels at top speed, slipping on the floor, does not
    hop (lizi 6 cm, jackal 12, pioneer3at 17 before floor contacts had their own friction
    reference)."""
    e = Engine(wall_world(0.6))
    entry = e.spawn_robot("r", load_robot(path))
    drive = drive_of(entry)
    settle(e)
    creep = highest_lift(e, ["r"], 750, lambda: drive.command(0.3, 0.0, e.time))
    assert creep < 0.005
    v = top_speed(entry, drive)
    assert highest_lift(e, ["r"], 750, lambda: drive.command(v, 0.0, e.time)) < 0.02


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_four_robots_pushing_into_each_other_stay_on_the_floor(path):
    """At the navigation speed (0.5 m/s) four robots that keep pushing into each other and a
    wall do not climb each other (lizis stacked 15 cm high, treads climbing treads)."""
    assert max(pile_up(path, 0.5, 8.0, seed) for seed in range(2)) < 0.02


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_pile_up_at_top_speed_lifts_no_robot_more_than_a_few_cm(path):
    """At top speed (the wheels' velocity limit: lizi 2.3 m/s, pioneer3at 3.2) robots pile up
    against each other and the wall without being thrown up (lizis rose 22-39 cm). Wedging
    stays possible where wheels stand proud of the body (a pioneer3at rode up another's
    wheels in 1-2 of 6 seeds with other floor settings, at < 0.7 m/s): two round wheels
    meeting at an angle are a ramp even without friction."""
    assert max(pile_up(path, math.inf, 3.0, seed) for seed in range(2)) < 0.04


def test_floor_contacts_are_explicit_pairs_with_the_movable_geoms_friction():
    e = Engine(None)
    e.spawn_robot("r", load_robot(ROBOTS / "lizi" / "urdf" / "lizi.urdf.xacro"))
    m = e.model
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "ground_plane/link/collision#0")
    collide = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    movable = np.flatnonzero(collide & (m.body_weldid[m.geom_bodyid] != 0))
    pairs = {(int(a), int(b)): k for k, (a, b) in enumerate(zip(m.pair_geom1, m.pair_geom2))}
    assert {(floor, int(g)) for g in movable} == set(pairs)
    wheel = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "r/front_left_wheel/collision#0")
    k = pairs[(floor, wheel)]
    assert m.pair_friction[k, 0] == m.pair_friction[k, 1] == 1.0  # the wheel's mu1
    assert m.pair_dim[k] == 3
    assert m.pair_solreffriction[k, 0] == FLOOR_FRICTION_TIMECONST
    assert tuple(m.pair_solref[k]) == tuple(m.geom_solref[wheel])
    # drive wheels touch everything else without friction, whatever wins the mixing
    assert m.geom_condim[wheel] == 1 and m.geom_priority[wheel] > 1
