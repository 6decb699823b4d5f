"""p3d ground truth: offsets, reference link, seeded noise."""

import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.plugins.p3d import P3dPlugin

from ..conftest import robot_text


def p3d_robot(extra: str):
    """The diffbot with extra p3d parameters."""
    anchor = "<frameName>/map</frameName>"
    return parse_urdf(robot_text("diffbot.urdf").replace(anchor, anchor + extra))


def reading(engine, entry):
    plugin = next(p for p in entry.plugins if isinstance(p, P3dPlugin))
    return plugin.measure(engine, engine.time)


def test_offsets_are_applied():
    e = Engine(None)
    ent = e.spawn_robot(
        "r",
        p3d_robot("<xyzOffsets>1 2 3</xyzOffsets><rpyOffsets>0 0 0.5</rpyOffsets>"),
        (4.0, 5.0, 0, 0, 0, 0),
    )
    r = reading(e, ent)
    np.testing.assert_allclose(r.position, [5.0, 7.0, 3.0], atol=1e-3)
    yaw = 2 * np.arctan2(r.orientation[2], r.orientation[3])
    assert yaw == pytest.approx(0.5, abs=1e-3)


def test_noise_is_seeded():
    def sample(seed):
        e = Engine(None, rng=np.random.default_rng(seed))
        ent = e.spawn_robot("r", p3d_robot("<gaussianNoise>0.05</gaussianNoise>"))
        return reading(e, ent).position

    a, b, c = sample(4), sample(4), sample(5)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c) and np.abs(a).max() < 0.3


def test_reference_link_frame_and_missing_body():
    e = Engine(None)
    ent = e.spawn_robot("r", p3d_robot(""), (1.0, 0, 0, 0, 0, 0))
    text = robot_text("diffbot.urdf").replace(
        "<frameName>/map</frameName>", "<frameName>base_link</frameName>"
    )
    rel = e.spawn_robot("q", parse_urdf(text), (1.0, 0, 0, 0, 0, 0))
    r = reading(e, rel)
    np.testing.assert_allclose(r.position, [0, 0, -0.05], atol=1e-3)  # footprint below base
    assert r.frame_id == "q/base_link" and reading(e, ent).frame_id == "map"
    bad = robot_text("diffbot.urdf").replace("<bodyName>base_footprint", "<bodyName>chassis")
    with pytest.raises(
        SimulationError, match="bodyName names link 'chassis', which the model lacks"
    ):
        e.spawn_robot("x", parse_urdf(bad))


def test_batched_readings_equal_single_ones(diffbot):
    from fleetsim.sim.plugins.p3d import P3dPlugin

    e = Engine(None)
    entries = [
        e.spawn_robot(
            f"r{i}",
            p3d_robot("<xyzOffsets>0 0 1</xyzOffsets><rpyOffsets>0.1 0 0.3</rpyOffsets>"),
            (i, 0, 0, 0, 0, i),
        )
        for i in range(3)
    ]
    for ent in entries:
        ent.plugins[0].command(0.4, 0.5, e.time)
    e.advance(0.3)
    e.step()  # cvel and xpos of the same (pre-integration) state, as readings see them
    plugins = [next(p for p in ent.plugins if isinstance(p, P3dPlugin)) for ent in entries]
    batch = P3dPlugin.measure_batch(e, plugins, e.time)
    for p, b in zip(plugins, batch):
        one = p.measure(e, e.time)
        for field in ("position", "orientation", "linear", "angular"):
            np.testing.assert_allclose(getattr(b, field), getattr(one, field), atol=1e-9)
        assert (b.frame_id, b.child_frame_id) == (one.frame_id, one.child_frame_id)


def test_batched_noise_equals_one_by_one_draws(diffbot):
    """Noisy, relative-frame and clean plugins together draw the seed's normals in the same
    order as measuring them one by one (relative-frame ones first)."""
    robots = [
        p3d_robot("<gaussianNoise>0.05</gaussianNoise>"),
        diffbot,
        parse_urdf(
            robot_text("diffbot.urdf").replace(
                "<frameName>/map</frameName>",
                "<frameName>base_link</frameName><gaussianNoise>0.02</gaussianNoise>",
            )
        ),
        p3d_robot("<gaussianNoise>0.01</gaussianNoise><xyzOffsets>1 0 0</xyzOffsets>"),
    ]

    def engine():
        e = Engine(None, rng=np.random.default_rng(5))
        for i, r in enumerate(robots):
            e.spawn_robot(f"r{i}", r, (i, 0, 0, 0, 0, 0)).plugins[0].command(0.3, 0.4, 0.0)
        e.advance(0.2)
        ps = [
            next(p for p in en.plugins if isinstance(p, P3dPlugin))
            for en in e.models.values()
            if en.kind == "robot"
        ]
        return e, ps

    e1, p1 = engine()
    e2, p2 = engine()
    batch = P3dPlugin.measure_batch(e1, p1, e1.time)
    rel = [p.measure(e2, e2.time) for p in p2 if p.ref]
    world = [p.measure(e2, e2.time) for p in p2 if not p.ref]
    singles = [world[0], world[1], rel[0], world[2]]
    for b, one in zip(batch, singles):
        for field in ("position", "linear", "angular"):
            np.testing.assert_allclose(getattr(b, field), getattr(one, field), atol=1e-9)
        assert b.covariance == one.covariance
    assert not np.array_equal(batch[0].position, e1.data.xpos[p1[0].body])  # noise was added
    np.testing.assert_array_equal(batch[1].position, e1.data.xpos[p1[1].body])
    assert e1.rng.random() == e2.rng.random()  # the same number of draws
