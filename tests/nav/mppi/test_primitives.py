"""MPPI's motion primitives: the sequences, the batch rows they take, and the local minimum
they get a robot out of (BARN world 141's gap, rebuilt from its two posts)."""

import math

import numpy as np
import pytest

from fleetsim.launch.packages import ASSETS
from fleetsim.nav.controllers.mppi import MPPIController, load_mppi
from fleetsim.nav.controllers.mppi.primitives import (
    SPEED_FRACTIONS,
    TURN_TIMES,
    primitive_sequences,
    set_primitive_rows,
)
from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_at, padded_footprint
from fleetsim.nav.costmap.inflation_layer import costs_from_distances
from fleetsim.runtime.params import load_yaml_file

DT = 0.1  # move_base's controller period in barn.launch
JACKAL = ASSETS / "launch" / "params" / "jackal"


def test_the_primitives_stand_drive_turn_and_turn_then_drive():
    seqs = primitive_sequences(56, 0.05, 0.5, 1.6)
    assert seqs.shape == (1 + 2 + 2 + 2 * 2 * len(TURN_TIMES), 56, 3)
    assert not seqs[0].any()  # stand still
    assert np.all(seqs[1, :, 0] == 0.5 * SPEED_FRACTIONS[0]) and not seqs[1, :, 2].any()
    assert np.all(seqs[3, :, 2] == 0.8) and np.all(seqs[4, :, 2] == -0.8)
    assert not seqs[:, :, 1].any()
    # a turn of 0.5 s (10 steps) at -0.8 rad/s, then 0.5 m/s straight
    seq = next(s for s in seqs[5:] if (s[:, 2] < 0).sum() == 10 and s[-1, 0] == 0.5)
    assert np.all(seq[:10, 0] == 0.0) and np.all(seq[10:, 2] == 0.0)


def test_primitives_replace_the_last_rows_of_the_noise():
    rng = np.random.default_rng(0)
    noise, sequence = rng.normal(size=(50, 8, 3)), rng.normal(size=(8, 3))
    before = noise.copy()
    prims = primitive_sequences(8, 0.05, 0.5, 1.0)
    set_primitive_rows(noise, sequence, prims)
    k = prims.shape[0]
    assert np.array_equal(noise[:-k], before[:-k])
    assert np.allclose(sequence + noise[-k:], prims)
    few = before[:3].copy()
    set_primitive_rows(few, sequence, prims)
    assert np.allclose(sequence + few, prims[:3])  # a batch smaller than the primitives


#: BARN world 141's two posts (radius 0.075 m) either side of the gap navfn plans through
POSTS = ((-2.025, 5.475), (-2.925, 5.775))
START = (-2.47, 5.36, 2.08)  # where the jackal stood for 85 s, heading 0.5 rad off the gap
ORIGIN = (-4.5, 3.5)


def world_141_gap() -> Costmap2D:
    m = Costmap2D(80, 100, 0.05, *ORIGIN)
    yy, xx = np.mgrid[0:100, 0:80]
    cx, cy = ORIGIN[0] + (xx + 0.5) * 0.05, ORIGIN[1] + (yy + 0.5) * 0.05
    lethal = np.zeros((100, 80), bool)
    for px, py in POSTS:
        lethal |= np.hypot(cx - px, cy - py) <= 0.075 + 0.025
    from scipy.ndimage import distance_transform_edt

    d = distance_transform_edt(~lethal)
    m.costs[:] = costs_from_distances(d, 0.05, 0.27, 0.30, 10.0)  # the jackal's costmap
    return m


def jackal_controller(m, **override):
    ns = load_yaml_file(JACKAL / "mppi_params.yaml")["MPPIController"]
    ns = {**ns, "controller_frequency": 1 / DT, **override}
    p, ack, critics = load_mppi(ns)
    common = load_yaml_file(JACKAL / "costmap_common_params.yaml")
    fp = padded_footprint(np.array(common["footprint"]), common["footprint_padding"])
    return MPPIController(m, fp, p, critics, np.random.default_rng(0), ack), fp


def drive(c, start, steps):
    x, y, th = start
    v = (0.0, 0.0, 0.0)
    poses = []
    for _ in range(steps):
        cmd = c.compute_velocity_commands((x, y, th), v)
        v = tuple(cmd)
        x += cmd.vx * math.cos(th) * DT
        y += cmd.vx * math.sin(th) * DT
        th += cmd.vtheta * DT
        poses.append((x, y, th))
    return np.array(poses)


def post_clearance(fp, poses):
    """The least distance (m) from any post's edge to the robot's footprint outline."""
    best = math.inf
    for x, y, th in poses:
        poly = footprint_at(fp, x, y, th)
        edges = np.stack([poly, np.roll(poly, -1, axis=0)], axis=1)
        for px, py in POSTS:
            p = np.array([px, py])
            a, b = edges[:, 0], edges[:, 1]
            t = np.clip(np.einsum("ij,ij->i", p - a, b - a) / ((b - a) ** 2).sum(1), 0, 1)
            d = np.hypot(*(a + t[:, None] * (b - a) - p).T).min() - 0.075
            best = min(best, d)
    return best


def gap_plan():
    ys = np.arange(START[1], 7.5, 0.025)
    return np.column_stack([np.full(len(ys), -2.47), ys, np.full(len(ys), math.pi / 2)])


@pytest.mark.parametrize("primitives", [True, False])
def test_the_jackal_facing_a_post_turns_and_drives_through_the_gap(primitives):
    c, fp = jackal_controller(world_141_gap(), primitive_samples=primitives)
    c.set_plan(gap_plan())
    poses = drive(c, START, 60)
    through = poses[:, 1].max() > 6.2  # past both posts
    if primitives:
        assert through, poses[-1]
        assert post_clearance(fp, poses) > 0.0  # not even the padded footprint touched a post
    else:  # Nav2's sampling alone: the local minimum the primitives are there for
        assert not through, poses[-1]
