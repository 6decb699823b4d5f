import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.errors import ParameterError, SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.build import quat_from_rpy

from .conftest import WILLOW, robot_text


def drive(engine, entry, vx, wz, seconds):
    drive_plugin = entry.plugins[0]
    out = []
    for _ in range(round(seconds / 0.05)):
        drive_plugin.command(vx, wz, engine.time)
        out += engine.advance(0.05)
    return out


def test_spawn_and_delete_keep_the_state_of_other_robots(diffbot):
    e = Engine(None)
    r1 = e.spawn_robot("r1", diffbot, (0, 0, 0, 0, 0, 0))
    drive(e, r1, 0.4, 0.2, 1.0)
    pos, quat = e.model_pose("r1")
    lin, ang = e.model_twist("r1")
    t = e.time
    e.spawn_robot("r2", diffbot, (3, 0, 0, 0, 0, 0))
    p2, q2 = e.model_pose("r1")
    np.testing.assert_array_equal(pos, p2)
    np.testing.assert_array_equal(quat, q2)
    np.testing.assert_allclose(e.model_twist("r1")[0], lin, atol=1e-12)
    assert e.time == t
    drive(e, r1, 0.4, 0.2, 0.5)
    p3, _ = e.model_pose("r1")
    e.delete_model("r2")
    np.testing.assert_array_equal(e.model_pose("r1")[0], p3)
    assert "r2" not in e.world_properties()["model_names"]
    with pytest.raises(SimulationError, match="no model named 'r2'"):
        e.model_pose("r2")


def test_same_model_many_times_and_duplicate_names(diffbot):
    e = Engine(None)
    for i in range(5):
        e.spawn_robot(f"bot{i}", diffbot, (i, 0, 0, 0, 0, 0))
    assert e.model.body("bot3/left_wheel").id > 0
    with pytest.raises(SimulationError, match="a model named 'bot1' already exists"):
        e.spawn_robot("bot1", diffbot)


def test_deterministic_bit_identical(diffbot):
    def run():
        e = Engine(None, rng=np.random.default_rng(7))
        a = e.spawn_robot("a", diffbot, (0, 0, 0, 0, 0, 0))
        b = e.spawn_robot("b", diffbot, (0, 1, 0, 0, 0, 0))
        drive(e, a, 0.3, 0.5, 0.5)
        drive(e, b, -0.2, 0.1, 0.5)
        return e.data.qpos.copy(), e.data.qvel.copy()

    (q1, v1), (q2, v2) = run(), run()
    assert q1.tobytes() == q2.tobytes() and v1.tobytes() == v2.tobytes()


def test_contacts_with_walls_are_reported(diffbot):
    from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc, WorldDesc, ground_plane

    wall = ModelDesc(
        "wall",
        (1.0, 0, 0.5, 0, 0, 0),
        True,
        [LinkDesc("link", geoms=[GeomDesc("box", (0.1, 4, 1))])],
    )
    e = Engine(WorldDesc("w", [ground_plane(), wall]))
    r = e.spawn_robot("r", diffbot, (0, 0, 0, 0, 0, 0))
    assert e.contacts() == []
    hits = []
    for _ in range(60):
        r.plugins[0].command(0.5, 0.0, e.time)
        e.advance(0.05)
        hits += e.contacts()
    assert hits and {(c.model1, c.model2) for c in hits} <= {("r", "wall"), ("wall", "r")}
    assert all("base_link" in (c.link1, c.link2) for c in hits)
    assert e.model_pose("r")[0][0] < 0.9  # the wall stopped it


def test_set_model_state_and_resets(diffbot):
    e = Engine(None)
    r = e.spawn_robot("r", diffbot, (1, 2, 0, 0, 0, 0.5))
    drive(e, r, 0.5, 0.0, 0.5)
    e.set_model_state("r", position=[5, 5, 0.0], orientation=quat_from_rpy(0, 0, 1.0))
    pos, quat = e.model_pose("r")
    np.testing.assert_allclose(pos, [5, 5, 0.0])
    np.testing.assert_allclose(quat, quat_from_rpy(0, 0, 1.0))
    e.set_model_state("r", linear=[0.0, 0.0, 0.0], angular=[0, 0, 1.0])
    np.testing.assert_allclose(e.model_twist("r")[1], [0, 0, 1.0], atol=1e-12)
    t = e.time
    e.reset_world()
    np.testing.assert_allclose(e.model_pose("r")[0], [1, 2, 0], atol=1e-12)
    assert e.time == t
    e.reset_simulation()
    assert e.time == 0.0
    with pytest.raises(SimulationError, match="model 'ground_plane' is static"):
        e.set_model_state("ground_plane", position=[0, 0, 0])


def test_pause_stops_physics_time(diffbot):
    e = Engine(None)
    e.spawn_robot("r", diffbot)
    e.paused = True
    e.advance(0.1)
    assert e.time == 0.0
    e.paused = False
    e.advance(0.1)
    assert e.time == pytest.approx(0.1)


def test_bad_plugins(diffbot, caplog, recwarn):
    text = robot_text("diffbot.urdf")
    e = Engine(None)
    unknown = text.replace("libgazebo_ros_joint_state_publisher.so", "libmy_fancy_plugin.so")
    with caplog.at_level("WARNING", logger="fleetsim"):
        e.spawn_robot("u", parse_urdf(unknown))
    said = [r.getMessage() for r in caplog.records if "unknown plugin" in r.getMessage()]
    assert said == [
        "model 'u': unknown plugin filename 'libmy_fancy_plugin.so'; ignored, the model "
        "spawns without it"
    ]  # once: in the log, not also as a Python warning
    assert not [w for w in recwarn if "unknown plugin" in str(w.message)]
    assert "u" in e.models
    wrong = text.replace("<wheelTorque>1</wheelTorque>", "<wheelTorque>strong</wheelTorque>")
    with pytest.raises(
        ParameterError,
        match=r"model 'w' plugin 'diff_drive'.*'wheelTorque' "
        r"must be float, got 'strong'",
    ):
        e.spawn_robot("w", parse_urdf(wrong))
    lacks = text.replace("<leftJoint>left_wheel_joint", "<leftJoint>left_whel_joint")
    with pytest.raises(
        SimulationError,
        match=r"leftJoint names 'left_whel_joint', a joint the "
        r"model lacks \(did you mean 'left_wheel_joint'",
    ):
        e.spawn_robot("j", parse_urdf(lacks))
    assert set(e.models) == {"ground_plane", "u"}
    e.spawn_robot("ok", diffbot)  # the failed spawns left nothing behind in the spec


def test_nan_commands_are_ignored_and_stop(diffbot, caplog):
    e = Engine(None)
    r = e.spawn_robot("r", diffbot)
    drive(e, r, 0.5, 0.0, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        drive(e, r, float("nan"), 0.0, 1.0)
    assert "ignoring non-finite command" in caplog.text
    assert np.linalg.norm(e.model_twist("r")[0]) < 0.02
    drive(e, r, 0.5, float("inf"), 0.2)
    assert np.linalg.norm(e.model_twist("r")[0]) < 0.2


def test_command_timeout_stops_the_robot(diffbot):
    e = Engine(None)
    r = e.spawn_robot("r", diffbot)
    drive(e, r, 0.5, 0.0, 1.0)
    assert e.model_twist("r")[0][0] > 0.4
    e.advance(1.5)  # no commands: timeout 0.5 s
    assert abs(e.model_twist("r")[0][0]) < 0.01


def test_spawn_sdf_model_and_world_properties():
    e = Engine(None)
    e.spawn_sdf(
        "box",
        "<sdf><model name='b'><link name='l'><inertial><mass>1</mass>"
        "</inertial><collision name='c'><geometry><box><size>.2 .2 .2</size></box>"
        "</geometry></collision></link></model></sdf>",
        (0, 0, 1, 0, 0, 0),
    )
    e.advance(1.0)
    assert e.model_pose("box")[0][2] == pytest.approx(0.1, abs=2e-3)
    assert e.world_properties()["model_names"] == ["ground_plane", "box"]


def test_idle_robot_stays_put(diffbot):
    e = Engine(None)
    e.spawn_robot("r", diffbot, (2.0, 1.0, 0, 0, 0, 0.3))
    heights = []
    for _ in range(40):
        e.advance(0.05)
        heights.append(e.model_pose("r")[0][2])
    assert np.hypot(*(e.model_pose("r")[0][:2] - [2.0, 1.0])) < 1e-3
    assert max(heights) < 1e-3  # no hopping on its contacts


def test_static_models_spawn_and_delete_in_the_world_body(diffbot):
    from fleetsim.sim.plugins.laser import LaserPlugin

    e = Engine(None)
    r = e.spawn_robot("r", diffbot, (0, 0, 0, 0, 0, 0))
    laser = next(p for p in r.plugins if isinstance(p, LaserPlugin))

    def ahead():
        return e.lasers.measure(e, [laser], e.time)[0].ranges[180]

    assert np.isinf(ahead())
    e.spawn_sdf(
        "post",
        "<sdf><model name='p'><static>1</static><link name='l'><collision "
        "name='c'><geometry><box><size>.2 .2 1</size></box></geometry></collision>"
        "</link></model></sdf>",
        (2.0, 0, 0.5, 0, 0, 0),
    )
    post = e.geom_model == e._model_names.index("post")
    assert post.any() and (e.model.geom_bodyid[post] == 0).all()
    assert ahead() == pytest.approx(2.0 - 0.1 - 0.1, abs=1e-3)  # laser 0.1 ahead of centre
    np.testing.assert_allclose(e.model_pose("post")[0], [2.0, 0, 0.5])
    with pytest.raises(SimulationError, match="model 'post' is static"):
        e.attacher.attach(e, "r", "base_link", "post", "l")
    e.delete_model("post")
    assert np.isinf(ahead())
    assert not any(e.model.geom(g).name.startswith("post/") for g in range(e.model.ngeom))


def test_ground_planes_sit_in_static_bodies_of_their_own(diffbot):
    """A plane in the world body makes MuJoCo walk the walls' whole bounding-volume tree for
    every link; it moves into a static body of its own with all its geom properties."""
    from fleetsim.sim.build import spec_from_world
    from fleetsim.sim.engine import load_world

    e = Engine(WILLOW)
    m = e.model
    (plane,) = np.flatnonzero(m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
    body = int(m.geom_bodyid[plane])
    assert body != 0 and m.body_weldid[body] == 0 and m.body_geomnum[body] == 1
    assert (m.geom_type[m.geom_bodyid == 0] == mujoco.mjtGeom.mjGEOM_BOX).all()  # the walls
    assert e._model_names[e.geom_model[plane]] == "ground_plane"
    ref = spec_from_world(load_world(WILLOW), 0.004)[0].compile()
    (want,) = np.flatnonzero(ref.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
    assert ref.geom(int(want)).name == m.geom(int(plane)).name
    for field in ("size", "pos", "quat", "friction", "contype", "conaffinity", "condim",
                  "priority", "solmix", "solref", "solimp", "margin", "gap", "group", "rgba",
                  "matid"):  # fmt: skip
        np.testing.assert_array_equal(
            getattr(m, f"geom_{field}")[plane], getattr(ref, f"geom_{field}")[want], field
        )
    # robots still stand on it, and the static model deletes with its plane
    e.spawn_robot("r", diffbot, (15.0, 30.0, 0, 0, 0, 0))
    e.advance(0.5)
    assert abs(e.model_pose("r")[0][2]) < 1e-3
    e.delete_model("ground_plane")
    assert not (e.model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE).any()
    assert not any(e.model.body(b).name.endswith(":plane") for b in range(e.model.nbody))
    e.advance(0.3)
    assert e.model_pose("r")[0][2] < -0.1  # falls without its floor


def test_a_robot_off_the_map_of_a_map_world_is_refused_naming_pose_and_extent(tmp_path):
    """A map world is the map's walls and an empty floor beyond: a start meant for another
    world (slam_explore's office starts in open_room) is an error, not an endless drive."""
    import fleetsim

    room = Path(fleetsim.__file__).parent / "assets" / "maps" / "open_room.yaml"
    robot = parse_urdf(robot_text("diffbot.urdf"))
    e = Engine(room)
    e.spawn_robot("inside", robot, (6.0, 6.0, 0, 0, 0, 0))
    with pytest.raises(
        SimulationError, match=r"'outside'.*\(26, 10\) is outside the map.*x 0\.\.14"
    ):
        e.spawn_robot("outside", robot, (26.0, 10.0, 0, 0, 0, 0))
    assert "outside" not in e.models and "inside" in e.models
