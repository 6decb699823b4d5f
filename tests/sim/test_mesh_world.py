"""A world built from a non-convex building mesh (fixtures/models/mesh_building, one closed OBJ
of two rooms and a corridor with doors): robots start free, drive through doors and are
stopped by walls, lasers and the collision parts match the true triangles."""

from __future__ import annotations

import functools
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.spatial import ConvexHull

from fleetsim.description import load_robot
from fleetsim.sim import Engine, decompose
from fleetsim.sim.mesh_assets import HULL_GROUP, RAY_GROUP, VISUAL_GROUP
from fleetsim.sim.mesh_files import triangle_mesh
from fleetsim.sim.plugins.base import DrivePlugin
from fleetsim.sim.plugins.laser import LaserPlugin

from .conftest import FIXTURES
from .ray_triangle import first_hit, horizontal

WORLD = FIXTURES / "mesh_building.world"
OBJ = FIXTURES / "models/mesh_building/meshes/building.obj"
BURGER = (
    Path(__file__).resolve().parents[2]
    / "src/fleetsim/assets/robots/turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
)


@pytest.fixture(autouse=True)
def models(monkeypatch, tmp_path):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(FIXTURES / "models"))
    monkeypatch.setenv("FLEETSIM_CACHE_DIR", str(tmp_path / "cache"))
    yield
    assert not Path("MUJOCO_LOG.TXT").exists()


@pytest.fixture(scope="module")
def burger():
    return load_robot(BURGER)


def no_mujoco_warnings(e: Engine) -> None:
    counts = [int(w.number) for w in e.data.warning]
    assert not any(counts), counts


@functools.cache
def building_triangles():
    """(T, 3, 3) corners of every triangle of the OBJ, m."""
    v, f = triangle_mesh(OBJ)
    return v[f]


#: the smallest positive float: hits strictly in front of the origin
AHEAD = np.nextafter(0.0, 1.0)


def exact_ranges(origin, angles, rmax):
    """First hit of horizontal rays against every triangle of the OBJ (Moller-Trumbore)."""
    tris = building_triangles()
    return np.array([first_hit(tris, origin, horizontal(ang), AHEAD, rmax) for ang in angles])


def test_building_is_cut_into_prisms_that_fill_exactly_its_volume():
    v, f = triangle_mesh(OBJ)
    d = decompose.decompose(v, f)
    assert d.methods == ["prisms"] and not d.convex and not d.problems
    volume = sum(ConvexHull(p).volume for p in d.parts)
    assert volume == pytest.approx(decompose.mesh_volume(v, f), rel=1e-9)


def test_robots_start_free_in_every_room_and_the_include_pose_is_used(burger):
    e = Engine(WORLD)
    assert e.world.models[-1].name == "building"
    assert e.world.models[-1].pose == (0, 0, 0, 0, 0, 0)  # the include's, not the model's
    names = [e.model.geom(i).name for i in range(e.model.ngeom)]
    hulls = [n for n in names if ":cvx" in n]
    assert len(hulls) > 1
    for name, pose in [("a", (1.5, 1.5)), ("b", (9.0, 2.0)), ("c", (6.0, 6.5))]:
        e.spawn_robot(name, burger, (*pose, 0, 0, 0, 0.3))
    e.advance(0.2)
    assert e.contacts() == []
    for name, pose in [("a", (1.5, 1.5)), ("b", (9.0, 2.0)), ("c", (6.0, 6.5))]:
        assert np.allclose(e.model_pose(name)[0][:2], pose, atol=0.01)
    no_mujoco_warnings(e)


def test_robot_drives_through_a_door_and_a_wall_stops_another(burger):
    e = Engine(WORLD)
    through = e.spawn_robot("through", burger, (3.0, 3.9, 0, 0, 0, np.pi / 2))
    blocked = e.spawn_robot("blocked", burger, (1.2, 3.9, 0, 0, 0, np.pi / 2))
    drives = [next(p for p in r.plugins if isinstance(p, DrivePlugin)) for r in (through, blocked)]
    touched = False
    for _ in range(120):  # 12 s at 0.22 m/s: 2.6 m north
        for plugin in drives:
            plugin.command(0.22, 0.0, e.time)
        e.advance(0.1)
        touched |= any("through" in (c.model1, c.model2) for c in e.contacts())
    x, y = e.model_pose("through")[0][:2]
    assert y > 6.0 and abs(x - 3.0) < 0.2  # in the corridor, through the door at x 2.5..3.5
    assert not touched
    by = e.model_pose("blocked")[0][1]
    assert 4.5 < by < 4.9  # pressed against the wall between room A and the corridor
    assert any("building" in (c.model1, c.model2) for c in e.contacts())
    no_mujoco_warnings(e)


def test_laser_and_collision_parts_match_the_true_walls_within_2cm(burger):
    e = Engine(WORLD)
    ent = e.spawn_robot("r", burger, (4.0, 3.0, 0, 0, 0, 0.4))
    e.advance(0.1)
    laser = next(p for p in ent.plugins if isinstance(p, LaserPlugin))
    laser.noise_std = laser.noise_mean = 0.0
    e.layouts.clear()
    got = e.lasers.measure(e, [laser], e.time)[0].ranges.astype(np.float64)
    origins, angles, _ = laser.rays(e)
    want = exact_ranges(origins[0], angles, laser.range_max)
    seen = np.isfinite(want)
    assert seen.sum() > len(want) // 4  # the burger's 3.5 m reaches the walls of room A
    assert np.array_equal(np.isfinite(got), seen)
    assert np.max(np.abs(got[seen] - want[seen])) < 0.02
    assert np.all(e.lasers.static_grid.prims[:, 0] == 2)  # the triangles, not the parts' boxes
    # the collision parts (what robots touch) against the true triangles, from free points
    m, d = e.model, e.data
    mask = np.zeros(6, np.uint8)
    mask[HULL_GROUP] = 1
    gid = np.zeros(1, np.int32)
    for origin in [(1.0, 1.0, 0.1), (5.0, 4.0, 0.5), (6.0, 2.5, 0.3), (3.0, 6.0, 1.0)]:
        for ang in np.linspace(0, 2 * np.pi, 90, endpoint=False):
            vec = np.array([np.cos(ang), np.sin(ang), 0.0])
            dist = mujoco.mj_ray(m, d, np.array(origin, float), vec, mask, 1, -1, gid)
            exact = exact_ranges(np.array(origin, float), [ang], 50.0)[0]
            assert abs(dist - exact) < 0.02, (origin, ang, dist, exact)
    no_mujoco_warnings(e)


def test_cameras_render_the_true_mesh_not_the_parts():
    e = Engine(WORLD)
    m = e.model
    hull = m.geom_group == HULL_GROUP
    assert hull.any()
    assert set(np.flatnonzero(m.geom_group == RAY_GROUP)).isdisjoint(np.flatnonzero(hull))
    rendered = (m.geom_group <= 2) & (m.geom_type == mujoco.mjtGeom.mjGEOM_MESH)
    _, f = triangle_mesh(OBJ)
    faces = {int(m.mesh_facenum[m.geom_dataid[g]]) for g in np.flatnonzero(rendered)}
    assert faces == {len(f)}  # the visual is the whole mesh, the hull parts are not drawn
    assert np.all(m.geom_group[(m.geom_contype != 0) & (m.geom_type == 7)] == HULL_GROUP)
    assert VISUAL_GROUP not in m.geom_group[hull]
    assert (m.geom_type[hull] == mujoco.mjtGeom.mjGEOM_BOX).sum() > len(np.flatnonzero(hull)) / 2


def test_rectangular_prisms_become_boxes_and_others_do_not():
    from fleetsim.sim.mesh_assets import box_of

    ring = np.array([[0, 0], [2, 0], [2, 1], [0, 1]], float) @ [[0.6, 0.8], [-0.8, 0.6]] + (5, 1)
    prism = np.c_[np.vstack([ring, ring]), [0] * 4 + [3] * 4]
    centre, half, yaw = box_of(prism)
    assert np.allclose(sorted(half), (0.5, 1, 1.5)) and np.allclose(centre, [*ring.mean(0), 1.5])
    c, si = np.cos(yaw), np.sin(yaw)
    corners = [
        centre[:2] + a * half[0] * np.array([c, si]) + b * half[1] * np.array([-si, c])
        for a in (-1, 1)
        for b in (-1, 1)
    ]
    assert all(np.min(np.linalg.norm(ring - k, axis=1)) < 1e-9 for k in corners)
    assert box_of(prism[::-1]) is not None  # any vertex order
    skew = prism.copy()
    skew[[1, 5], 0] += 0.3  # a trapezoid
    assert box_of(skew) is None
    assert box_of(prism[:6]) is None


def test_second_build_reads_the_decomposition_from_the_cache(monkeypatch):
    first = Engine(WORLD)
    files = list(decompose.cache_dir().glob("convex/*.npz"))
    assert len(files) == 1
    stamp = files[0].stat().st_mtime_ns

    def fail(*args, **kwargs):
        raise AssertionError("decomposed again instead of reading the cache")

    monkeypatch.setattr(decompose, "decompose", fail)
    second = Engine(WORLD)
    assert files[0].stat().st_mtime_ns == stamp
    assert second.model.ngeom == first.model.ngeom
    np.testing.assert_array_equal(second.model.geom_aabb, first.model.geom_aabb)


def test_depth_camera_sees_the_true_walls_through_a_door():
    from fleetsim.sim.plugins.camera import DepthCameraPlugin

    waffle = load_robot(BURGER.parents[2] / "turtlebot3_waffle/urdf/turtlebot3_waffle.urdf.xacro")
    e = Engine(WORLD)
    ent = e.spawn_robot("w", waffle, (3.0, 3.2, 0, 0, 0, np.pi / 2))
    e.advance(0.1)
    cam = next(p for p in ent.plugins if isinstance(p, DepthCameraPlugin))
    depth = cam.render(e, depth=True)
    origin = e.data.cam_xpos[cam.cam_id].copy()
    axis = -e.data.cam_xmat[cam.cam_id].reshape(3, 3)[:, 2]  # MuJoCo cameras look along -z
    h, w = depth.shape
    for col in (w // 2, w // 8, 7 * w // 8):  # through the door, and the wall beside it
        ray = np.linalg.inv(cam.K) @ [col + 0.5, h / 2 + 0.5, 1.0]  # optical: x right, y down
        R = e.data.cam_xmat[cam.cam_id].reshape(3, 3)
        d = R @ [ray[0], -ray[1], -1.0]
        d /= np.linalg.norm(d)
        exact = first_hit(building_triangles(), origin, d, AHEAD)
        assert abs(depth[h // 2, col] - exact * (d @ axis)) < 0.02, col
    assert depth[h // 2, w // 2] > 4.0  # the corridor's far wall, seen through the door
    no_mujoco_warnings(e)


def test_lasers_see_a_convex_static_mesh_as_its_triangles(tmp_path):
    """An octagonal pillar (convex): one collision part, and rays hit its faces, not the
    square bounding box a mesh geom would otherwise be sliced into."""
    from fleetsim.sim import raycast
    from fleetsim.sim.sdf import load_sdf_model
    from fleetsim.sim.world import WorldDesc, ground_plane

    ang = np.arange(8) * np.pi / 4
    ring = np.c_[np.cos(ang), np.sin(ang)]
    v = np.r_[np.c_[ring, np.zeros(8)], np.c_[ring, np.full(8, 2.0)]]
    f = [(k, (k + 1) % 8, 8 + (k + 1) % 8) for k in range(8)]
    f += [(k, 8 + (k + 1) % 8, 8 + k) for k in range(8)]
    f += [(0, k + 1, k) for k in range(1, 7)] + [(8, 8 + k, 8 + k + 1) for k in range(1, 7)]
    obj = tmp_path / "pillar.obj"
    obj.write_text(
        "\n".join(
            [f"v {a} {b} {c}" for a, b, c in v] + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]
        )
    )
    model = load_sdf_model(
        f"<sdf version='1.6'><model name='pillar'><static>true</static><link name='l'>"
        f"<collision name='c'><geometry><mesh><uri>{obj}</uri></mesh></geometry></collision>"
        "</link></model></sdf>",
        str(tmp_path / "pillar.sdf"),
    )
    e = Engine(WorldDesc("w", [ground_plane(), model]))
    names = [e.model.geom(i).name for i in range(e.model.ngeom)]
    assert sum(":cvx" in n for n in names) == 1
    # a ray at a face's middle: 4 - cos(pi/8) to the face (the bounding square: 4 - 1/cos)
    a = np.pi / 8
    origin = np.array([[4 * np.cos(a), 4 * np.sin(a), 1.0]])
    got = raycast.cast(e.lasers.static_grid, origin, np.array([a + np.pi]), 0.0, 10.0, -1)
    assert got[0] == pytest.approx(4 - np.cos(a), abs=1e-6)
    no_mujoco_warnings(e)
