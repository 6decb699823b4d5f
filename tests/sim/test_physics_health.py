"""Physics that never fails silently (``sim.health``).

Every shipped robot driven at its top speed (wheel joint velocity limit times wheel radius)
into a wall and into another robot raises no MuJoCo warning; injected instabilities (a NaN
force, a NaN control, a broken model) raise `PhysicsInstability` naming the robot, body and
joint; through ``fleetsim launch`` the run stops with a one-line error and a readable recording.
Each test runs in a temporary directory, where a ``MUJOCO_LOG.TXT`` would show up.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fleetsim.description import load_robot
from fleetsim.errors import PhysicsInstability
from fleetsim.sim import Engine
from fleetsim.sim.plugins.base import DrivePlugin
from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc, WorldDesc, ground_plane

from .conftest import FIXTURES, unread

ROBOTS = Path(__file__).resolve().parents[2] / "src" / "fleetsim" / "assets" / "robots"
FILES = sorted(ROBOTS.glob("*/urdf/*.urdf.xacro"))


pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def drive_of(entry) -> DrivePlugin:
    return next(p for p in entry.plugins if isinstance(p, DrivePlugin))


def top_speed(entry, drive) -> float:
    """Wheel surface speed at the wheel joints' velocity limit, m/s."""
    limits = [entry.robot.joints[j].limit for j in drive.left + drive.right]
    return min(lim.velocity for lim in limits if lim is not None) * drive.radius


def tilt(e: Engine, name: str) -> float:
    """Angle (rad) between the model root's z axis and the world's."""
    w, x, y, _ = e.model_pose(name)[1]
    return math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y))))


def run_clean(e: Engine, commands, seconds: float) -> float:
    """Drive for ``seconds``; no warning counter may trip and accelerations stay sane.
    Returns the largest tilt (rad) any driven robot reached."""
    unread(e)
    most = 0.0
    for _ in range(round(seconds / 0.05)):
        for drive, vx, wz in commands:
            drive.command(vx, wz, e.time)
        e.advance(0.05)
        assert not e.data.warning.number.any()
        assert np.isfinite(e.data.qacc).all() and np.abs(e.data.qacc).max() < 1e5
        most = max([most, *(tilt(e, d.ctx.model) for d, _, _ in commands)])
    return most


@pytest.mark.parametrize("path", FILES, ids=[p.parts[-3] for p in FILES])
def test_robot_at_top_speed_into_a_wall_stays_sane(path):
    wall = ModelDesc(
        "wall", (1.2, 0, 0.5, 0, 0, 0), True, [LinkDesc("l", geoms=[GeomDesc("box", (0.1, 6, 1))])]
    )
    e = Engine(WorldDesc("w", [ground_plane(), wall]))
    entry = e.spawn_robot("bot", load_robot(path), (0, 0, 0, 0, 0, 0.4))
    drive = drive_of(entry)
    run_clean(e, [(drive, top_speed(entry, drive), 0.0)], 1.5)
    assert e.model_pose("bot")[0][0] < 1.2  # the wall held


@pytest.mark.parametrize("path", FILES, ids=[p.parts[-3] for p in FILES])
def test_robots_at_top_speed_into_each_other_stay_sane(path):
    robot = load_robot(path)
    e = Engine(None)
    a, b = e.spawn_robots(
        [("a", robot, (0, 0, 0, 0, 0, 0)), ("b", robot, (1.5, 0.1, 0, 0, 0, math.pi - 0.3))]
    )
    da, db = drive_of(a), drive_of(b)
    v = top_speed(a, da)
    run_clean(e, [(da, v, 0.0), (db, v, 1.0)], 1.5)


@pytest.mark.parametrize("path", FILES, ids=[p.parts[-3] for p in FILES])
def test_at_navigation_speed_robots_push_walls_and_robots_without_climbing(path):
    # 0.5 m/s, the shipped move_base limit; at top speed four-wheel drives may ride up (real
    # ones do), but at this speed a wall or another robot stops them flat on the ground
    wall = ModelDesc(
        "wall", (1.2, 0, 0.5, 0, 0, 0), True, [LinkDesc("l", geoms=[GeomDesc("box", (0.1, 6, 1))])]
    )
    robot = load_robot(path)
    e = Engine(WorldDesc("w", [ground_plane(), wall]))
    entry = e.spawn_robot("bot", robot, (0, 0, 0, 0, 0, 0.4))
    drive = drive_of(entry)
    v = min(0.5, top_speed(entry, drive))
    assert run_clean(e, [(drive, v, 0.0)], 2.0) < 0.15
    e = Engine(None)
    a, b = e.spawn_robots(
        [("a", robot, (0, 0, 0, 0, 0, 0)), ("b", robot, (1.5, 0.1, 0, 0, 0, math.pi - 0.3))]
    )
    assert run_clean(e, [(drive_of(a), v, 0.0), (drive_of(b), v, 1.0)], 2.0) < 0.15


def test_nan_force_names_robot_body_and_joint(diffbot, caplog):
    caplog.set_level(logging.DEBUG, logger="fleetsim.mujoco")
    e = Engine(None)
    e.spawn_robot("bot", diffbot)
    e.advance(0.05)
    e.data.xfrc_applied[e.root_body("bot"), 2] = np.nan
    with pytest.raises(
        PhysicsInstability,
        match=r"t = 0\.0\d\d s: NaN, infinite or huge acceleration \(qacc\) at robot 'bot', "
        r"body 'base_footprint', joint 'free' .*likely cause: NaN or infinite applied force on "
        r"bot/base_footprint",
    ):
        e.advance(0.05)
    # MuJoCo's own text went to fleetsim's log (at debug level: the error says more), not to
    # MUJOCO_LOG.TXT
    texts = [r for r in caplog.records if r.getMessage().startswith("MuJoCo: ")]
    assert texts and {r.levelno for r in texts} == {logging.DEBUG}
    assert "Nan, Inf or huge value in QACC at DOF 0" in texts[0].getMessage()
    # no auto-reset: the world stays as the failed step left it, until it is reset on purpose
    assert not np.isfinite(e.data.qpos).all()
    e.data.xfrc_applied[:] = 0.0
    e.reset_world()
    e.advance(0.2)
    assert np.isfinite(e.data.qpos).all() and not e.data.warning.number.any()


def test_nan_control_is_an_instability(diffbot):
    e = Engine(None)
    entry = e.spawn_robot("bot", diffbot)
    e.advance(0.05)
    act = mujoco.mj_name2id(e.model, mujoco.mjtObj.mjOBJ_ACTUATOR, entry.actuators[0])
    e.drives.control = lambda engine, t: None  # the servo would overwrite the control
    e.data.ctrl[act] = np.nan
    with pytest.raises(
        PhysicsInstability,
        match=rf"huge command nan on actuator '{entry.actuators[0]}' \(robot 'bot', "
        r"body '\w+_wheel', joint '\w+'.*likely cause: a NaN command",
    ):
        e.advance(0.05)


@pytest.mark.parametrize(
    "field, value",
    [("position", [np.nan, 0.0, 0.1]), ("linear", [0.0, np.inf, 0.0]), ("orientation", [0] * 4)],
)
def test_set_model_state_refuses_a_non_finite_state_by_field(diffbot, field, value):
    from fleetsim.errors import SimulationError

    e = Engine(None)
    e.spawn_robot("bot", diffbot)
    before = e.data.qpos.copy()
    with pytest.raises(SimulationError, match=rf"set_model_state 'bot': {field} "):
        e.set_model_state("bot", **{field: value})
    assert np.array_equal(e.data.qpos, before)  # nothing half-written


def test_a_nan_state_written_past_the_checks_is_named_as_such(diffbot):
    """A velocity set to NaN directly (a plugin writing qvel) is the cause the error names,
    not a NaN-deep contact or a runaway at nan m/s."""
    e = Engine(None)
    e.spawn_robot("bot", diffbot)
    e.advance(0.05)
    e.data.qvel[0] = np.nan
    with pytest.raises(
        PhysicsInstability,
        match=r"robot 'bot'.*likely cause: non-finite state: the velocity of joint 'free' .*"
        r"was already NaN or infinite before this step",
    ):
        e.advance(0.05)


@pytest.mark.parametrize("kind", ["mjWARN_CONTACTFULL", "mjWARN_CNSTRFULL"])
def test_full_contact_memory_is_an_error(diffbot, kind):
    """MuJoCo drops contacts when its arena is full; the engine stops (flagged as MuJoCo does)."""
    from fleetsim.errors import PhysicsBufferFull

    e = Engine(None)
    e.spawn_robot("bot", diffbot)
    e.data.warning.number[getattr(mujoco.mjtWarning, kind)] = 1
    with pytest.raises(PhysicsBufferFull, match=r"ran out of memory for .* pass through each"):
        e.advance(0.01)


@pytest.mark.parametrize("path", FILES, ids=[p.parts[-3] for p in FILES])
def test_robot_tossed_spinning_with_its_drive_on_stays_sane(path):
    """Two lizis thrown up by a pile-up in the 10-robot soak tumbled at ~40 rad/s; with the
    implicit-fast integrator (no gyroscopic derivatives) one gained spin every step to NaN in
    0.8 s of free flight. Each shipped robot, tossed up spinning about all axes while its
    drive is commanded, keeps a bounded spin, lands, and raises no warning."""
    e = Engine(WorldDesc("w", [ground_plane()]))
    entry = e.spawn_robot("r", load_robot(path), (0, 0, 3.0, 0, 0, 0))
    drive = drive_of(entry)
    free = e.model.jnt_dofadr[e.model.body_jntadr[e.root_body("r")]]
    e.data.qvel[free : free + 6] = (0.0, 0.0, 5.0, 40.0, -35.0, -38.0)
    spin0 = float(np.linalg.norm(e.data.qvel[free + 3 : free + 6]))
    unread(e)
    most = 0.0
    for _ in range(round(4.0 / 0.05)):
        drive.command(top_speed(entry, drive), 0.5, e.time)
        e.advance(0.05)
        assert not e.data.warning.number.any()
        assert np.isfinite(e.data.qacc).all()
        most = max(most, float(np.linalg.norm(e.data.qvel[free + 3 : free + 6])))
    assert most <= 1.5 * spin0, f"spin grew from {spin0:.0f} to {most:.0f} rad/s"
    assert e.model_pose("r")[0][2] < 1.0  # it landed


def test_flung_robot_is_named_as_a_runaway(diffbot):
    """A robot spinning far too fast to integrate ends in NaN in the air; the cause names the
    motion it already had, not the last step."""
    e = Engine(None)
    e.spawn_robot("bot", diffbot, (0, 0, 10, 0, 0, 0))
    e.data.qvel[3:6] = (3e5, 2e5, 1e5)
    with pytest.raises(
        PhysicsInstability,
        match=r"robot 'bot', body 'base_footprint', joint 'free'.*likely cause: runaway "
        r"motion: it was already moving at .* (m|rad)/s on joint 'free' \(floating base, "
        r".* before this step, touching nothing",
    ):
        e.advance(1.0)


def test_broken_model_names_the_light_link():
    e = Engine(None)
    e.spawn_robot("bad", load_robot(FIXTURES / "broken_flapper.urdf"))
    with pytest.raises(
        PhysicsInstability,
        match=r"at robot 'bad', body 'flap_link', joint 'flap', DOF 6; likely cause: bad "
        r"inertia: link 'flap_link' of 1e-06 kg .*try: give link 'flap_link' a realistic",
    ):
        e.advance(1.0)


def test_launch_that_blows_up_exits_nonzero_with_a_readable_recording(tmp_path, capsys):
    from fleetsim.cli.main import main
    from fleetsim.record import BagReader

    launch = tmp_path / "broken.launch"
    launch.write_text(
        "<launch>\n"
        '  <include file="$(find gazebo_ros)/launch/empty_world.launch"/>\n'
        f'  <param name="robot_description" textfile="{FIXTURES / "broken_flapper.urdf"}"/>\n'
        '  <node name="spawn" pkg="gazebo_ros" type="spawn_model"\n'
        '        args="-urdf -param robot_description -model bad"/>\n'
        "</launch>\n"
    )
    bag = tmp_path / "run.mcap"
    code = main(["launch", str(launch), "--duration", "2", "--record", str(bag), "--no-bridge"])
    assert code == 1
    err = capsys.readouterr().err.replace("\n", " ")
    assert "error: physics instability at t = " in err
    assert "Traceback" not in err
    reader = BagReader(bag)
    assert reader.complete  # finalised: footer and closing magic written
    assert "/clock" in {t.name for t in reader.info().topics}
    assert sum(1 for _ in reader.messages(["/clock"])) > 0


def test_steps_newton_does_not_finish_are_redone_with_cg(skidbot):
    """With the guard's cap at 0 every Newton step counts as unfinished: each is redone with CG
    from the state before it, and the run equals one stepped with CG throughout, bit for bit."""

    def run(solver):
        e = Engine(None)
        entry = e.spawn_robot("bot", skidbot)
        e.model.opt.solver = solver
        e.solver_guard.cap = 0
        for _ in range(10):
            drive_of(entry).command(0.4, 0.5, e.time)
            e.advance(0.02)
        return e

    newton, cg = run(mujoco.mjtSolver.mjSOL_NEWTON), run(mujoco.mjtSolver.mjSOL_CG)
    assert newton.solver_guard.redone == 50 and cg.solver_guard.redone == 0
    assert newton.data.qpos.tobytes() == cg.data.qpos.tobytes()
    assert newton.data.qvel.tobytes() == cg.data.qvel.tobytes()
