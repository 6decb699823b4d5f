"""Batched planar laser casting checked against MuJoCo's exact (slow) mj_ray."""

import mujoco
import numpy as np
import pytest

from fleetsim.sim import Engine
from fleetsim.sim.plugins.laser import LaserPlugin

from .conftest import BARN, WILLOW


def reference_ranges(engine, laser, robot_name):
    """mj_ray per beam over collision geoms of everything but the sensing robot."""
    m, d = engine.model, engine.data
    saved = m.geom_rgba.copy()
    collide = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    own = engine.geom_model == engine._model_names.index(robot_name)
    plane = m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
    m.geom_rgba[~collide | own | plane, 3] = 0.0  # mj_ray skips invisible geoms
    origins, angles, _ = laser.rays(engine)
    out = np.empty(len(angles))
    hit_model = np.full(len(angles), -1)
    gid = np.zeros(1, np.int32)
    for i, (o, a) in enumerate(zip(origins, angles)):
        vec = np.array([np.cos(a), np.sin(a), 0.0])
        dist = mujoco.mj_ray(m, d, o + laser.range_min * vec, vec, None, 1, -1, gid)
        dist = dist + laser.range_min if dist >= 0 else np.inf
        out[i] = dist if dist <= laser.range_max else np.inf
        hit_model[i] = engine.geom_model[gid[0]] if dist >= 0 else -1
    m.geom_rgba[:] = saved
    return out, hit_model


def scan_now(engine, laser):
    return engine.lasers.measure(engine, [laser], engine.time)[0].ranges.astype(np.float64)


@pytest.mark.parametrize(
    ("world", "pose"),
    [(BARN, (-2.25, 3.0, 0.0, 0.0, 0.0, 1.2)), (WILLOW, (10.0, 10.0, 0.0, 0.0, 0.0, 0.3))],
)
def test_laser_matches_mj_ray(world, pose, diffbot):
    e = Engine(world)
    ent = e.spawn_robot("r1", diffbot, pose)
    other = (pose[0] + 1.0 * np.cos(pose[5]), pose[1] + 1.0 * np.sin(pose[5]), 0, 0, 0, 2.0)
    e.spawn_robot("r2", diffbot, other)
    e.advance(0.2)
    laser = next(p for p in ent.plugins if isinstance(p, LaserPlugin))
    got = scan_now(e, laser)
    want, hit_model = reference_ranges(e, laser, "r1")
    hit = np.isfinite(want)
    assert hit.sum() > 50
    np.testing.assert_array_equal(np.isfinite(got), hit)
    # static world: exact up to float32; the other robot is sliced as upright shapes while
    # it rocks slightly on its wheels, so allow millimetres there
    robot = hit_model == e._model_names.index("r2")
    assert robot.sum() > 3
    np.testing.assert_allclose(got[hit & ~robot], want[hit & ~robot], atol=1e-5)
    np.testing.assert_allclose(got[robot], want[robot], atol=5e-3)
    # the robot ahead is seen at about 1 m minus its radius
    front = got[len(got) // 2]
    assert 0.6 < front < 0.85


def test_laser_noise_is_seeded(diffbot):
    from fleetsim.description import parse_urdf

    text = diffbot.to_urdf().replace(
        "<range>",
        "<noise><type>gaussian</type><mean>0.0</mean><stddev>0.01</stddev></noise><range>",
        1,
    )
    noisy = parse_urdf(text)
    scans = []
    for seed in (1, 1, 2):
        e = Engine(WILLOW, rng=np.random.default_rng(seed))
        ent = e.spawn_robot("r", noisy, (10.0, 10.0, 0, 0, 0, 0))
        laser = next(p for p in ent.plugins if isinstance(p, LaserPlugin))
        scans.append(scan_now(e, laser))
    np.testing.assert_array_equal(scans[0], scans[1])
    assert not np.array_equal(scans[0], scans[2])
    finite = np.isfinite(scans[0])
    assert 0.001 < np.std(scans[0][finite] - scans[2][finite]) < 0.05


@pytest.mark.parametrize("roll", [0.0, np.pi])
def test_a_laser_mounted_upside_down_sweeps_clockwise(roll):
    """Rolled 180 degrees, the sensor's +y (beam angle +pi/2) points to the robot's right."""
    from fleetsim.description import parse_urdf
    from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc, WorldDesc, ground_plane

    from .conftest import replace_plugin_param, robot_text

    text = replace_plugin_param(
        robot_text("diffbot.urdf"), "<pose>0 0 0 0 0 0</pose>", f"<pose>0 0 0 {roll} 0 0</pose>"
    )
    wall = ModelDesc(
        "wall", (0, -1.5, 0.5, 0, 0, 0), True, [LinkDesc("l", geoms=[GeomDesc("box", (6, 0.2, 1))])]
    )
    e = Engine(WorldDesc("w", [ground_plane(), wall]))
    ent = e.spawn_robot("r", parse_urdf(text))
    e.advance(0.1)
    laser = next(p for p in ent.plugins if isinstance(p, LaserPlugin))
    ranges = scan_now(e, laser)
    angles = laser.angle_min + laser.increment * np.arange(laser.samples)
    left, right = np.argmin(abs(angles - np.pi / 2)), np.argmin(abs(angles + np.pi / 2))
    seen, blind = (right, left) if roll == 0.0 else (left, right)
    assert ranges[seen] == pytest.approx(1.4, abs=0.01) and np.isinf(ranges[blind])
    np.testing.assert_allclose(ranges, reference_ranges(e, laser, "r")[0], atol=1e-5)


def test_noisy_ranges_equal_numpys_bit_for_bit():
    """The fused noise kernel gives the array expression it replaced, bit for bit, with one
    normal per beam, used where a noisy beam hits."""
    from fleetsim.sim.lasers import noisy_ranges

    rng = np.random.default_rng(3)
    n = 5000
    ranges = rng.uniform(0.0, 12.0, n)
    ranges[rng.random(n) < 0.3] = np.inf
    noisy = rng.random(n) < 0.7
    mean = rng.normal(0.0, 0.01, n)
    std = rng.uniform(0.0, 0.5, n)  # large: many beams clipped at either end
    rmin, rmax = np.full(n, 0.1), np.full(n, 10.0)
    ranges[:5] = [0.1, 10.0, 0.05, np.inf, 10.5]
    hit = np.flatnonzero(noisy & np.isfinite(ranges))
    z = rng.standard_normal(n)
    want = ranges.copy()
    want[hit] = np.clip(ranges[hit] + mean[hit] + std[hit] * z[hit], rmin[hit], rmax[hit])
    want = want.astype(np.float32)
    got = np.empty(n, np.float32)
    noisy_ranges(ranges, noisy, mean, std, rmin, rmax, z, got)
    assert got.tobytes() == want.tobytes()
    assert (got[hit] == 0.1).sum() > 10 and (got[hit] == np.float32(10.0)).sum() > 10


def test_scan_noise_streams_are_per_scan_and_per_laser():
    """Each scan of each laser draws its own stream: the same key, laser and scan give the
    same draws whatever was drawn before; another scan or laser gives others."""
    from fleetsim.sim.lasers import scan_noise

    a = scan_noise(7, 11, 3, 720)
    scan_noise(7, 11, 2, 720)  # another scan drawn in between changes nothing
    np.testing.assert_array_equal(a, scan_noise(7, 11, 3, 720))
    for other in (scan_noise(7, 11, 4, 720), scan_noise(7, 12, 3, 720), scan_noise(8, 11, 3, 720)):
        assert abs(np.corrcoef(a, other)[0, 1]) < 0.15
    assert abs(a.mean()) < 0.15 and 0.9 < a.std() < 1.1


def _noisy_engine(diffbot, seed=1):
    from fleetsim.description import parse_urdf

    text = diffbot.to_urdf().replace(
        "<range>",
        "<noise><type>gaussian</type><mean>0.0</mean><stddev>0.01</stddev></noise><range>",
        1,
    )
    e = Engine(WILLOW, rng=np.random.default_rng(seed))
    ent = e.spawn_robot("r", parse_urdf(text), (10.0, 10.0, 0, 0, 0, 0))
    ent.plugins[0].command(0.5, 0.5, e.time)  # moving: a scan cast late must not see it moved
    return e, next(p for p in ent.plugins if isinstance(p, LaserPlugin))


def test_a_scan_is_cast_when_read_and_reads_the_same_either_way(diffbot):
    """Readings are cast only when their ranges are read, with the state of their instant:
    a scan read late equals the same scan read at once, and skipping scans unread does not
    change the ones read after (their noise is keyed by the scan, not drawn in turn)."""
    from fleetsim.sim.messages import LazyLaserScan, scan_msg

    runs = []
    for read_every in (1, 3):
        e, laser = _noisy_engine(diffbot)
        kept = []
        for k in range(6):
            e.advance(0.05)
            (r,) = e.lasers.measure(e, [laser], e.time)
            assert not r.cast  # nothing cast yet
            if k % read_every == 0:
                kept.append((k, r))
                if read_every == 1:
                    _ = r.ranges  # read at once
        runs.append({k: r.ranges for k, r in kept})  # read_every 3: read late, moved since
    for k, ranges in runs[1].items():
        np.testing.assert_array_equal(ranges, runs[0][k])
    finite = np.isfinite(runs[0][0]) & np.isfinite(runs[0][3])
    assert np.abs(runs[0][0][finite] - runs[0][3][finite]).mean() > 0.02  # it moved meanwhile
    # the message stands for a LaserScan until read, then holds the same ranges
    e, laser = _noisy_engine(diffbot)
    (r,) = e.lasers.measure(e, [laser], e.time)
    msg = scan_msg(r)
    assert isinstance(msg, LazyLaserScan) and not r.cast
    assert len(msg.ranges) == laser.samples and r.cast
    np.testing.assert_array_equal(msg.ranges, r.ranges)


def test_bounding_circles_equal_the_numpy_grouping():
    """The compiled grouping gives what a stable sort, ``unique`` and ``reduceat`` over the
    primitives' bounding boxes gave, bit for bit."""
    from fleetsim.sim import raycast
    from fleetsim.sim.lasers import bounding_circles

    rng = np.random.default_rng(5)
    owner = np.sort(rng.integers(3, 9, 40)).astype(np.int64)
    prims = np.zeros((40, 7))
    prims[:, 0] = rng.integers(0, 2, 40)  # segments and circles
    prims[:, 1:5] = rng.normal(0.0, 3.0, (40, 4))
    prims[:, 3] = np.where(prims[:, 0] == raycast.SEGMENT, prims[:, 3], abs(prims[:, 3]))
    centres, radii, ids, start = bounding_circles(prims, owner)
    want_ids, first = np.unique(owner, return_index=True)
    want_start = np.append(first, len(owner))
    seg = prims[:, 0] == raycast.SEGMENT
    lo = np.where(
        seg[:, None], np.minimum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] - prims[:, 3:4]
    )
    hi = np.where(
        seg[:, None], np.maximum(prims[:, 1:3], prims[:, 3:5]), prims[:, 1:3] + prims[:, 3:4]
    )
    lo_b, hi_b = np.minimum.reduceat(lo, first, axis=0), np.maximum.reduceat(hi, first, axis=0)
    assert ids.tolist() == want_ids.tolist() and start.tolist() == want_start.tolist()
    assert centres.tobytes() == ((lo_b + hi_b) / 2).tobytes()
    assert radii.tobytes() == (np.linalg.norm(hi_b - lo_b, axis=1) / 2).tobytes()
    empty = bounding_circles(np.zeros((0, 7)), np.zeros(0, np.int64))
    assert [a.shape for a in empty] == [(0, 2), (0,), (0,), (1,)]


def test_robot_bodies_group_the_primitives_of_each_model(diffbot):
    """A laser's view of the other robots: one group per robot, every primitive of its geoms."""
    e = Engine(WILLOW)
    for i in range(3):
        e.spawn_robot(f"r{i}", diffbot, (10.0 + i, 10.0, 0, 0, 0, 0.5 * i))
    e.advance(0.1)
    centres, radii, ids, start, prims = e.lasers.bodies(e)
    assert sorted(e._model_names[k] for k in ids) == ["r0", "r1", "r2"]
    for k, b in enumerate(ids):
        mine = prims[start[k] : start[k + 1]]
        assert len(mine) > 0
        ends = np.where(mine[:, :1] == 0, mine[:, 3:5], mine[:, 1:3])  # segments' far ends
        xy = np.concatenate([mine[:, 1:3], ends])
        assert np.all(np.linalg.norm(xy - centres[k], axis=1) <= radii[k] + 1e-12)
        spawned_x = 10.0 + int(e._model_names[b][1:])
        assert abs(centres[k, 0] - spawned_x) < 0.5 and abs(centres[k, 1] - 10.0) < 0.5
