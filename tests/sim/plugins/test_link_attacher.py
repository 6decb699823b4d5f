"""Attach a marker to a robot, drive, detach: the marker follows, then stays."""

import numpy as np
import pytest

from fleetsim.errors import SimulationError
from fleetsim.sim import Engine

from .test_diff_drive import run

MARKER = """<sdf version="1.6"><model name="marker"><link name="link">
<inertial><mass>0.05</mass></inertial>
<collision name="c"><geometry><box><size>0.1 0.1 0.02</size></box></geometry></collision>
</link></model></sdf>"""


def relative(e, a, b):
    pa, _ = e.model_pose(a)
    pb, _ = e.model_pose(b)
    return pb - pa


def test_attach_moves_marker_with_robot_then_detach_releases(diffbot):
    e = Engine(None)
    r = e.spawn_robot("robot", diffbot, (0, 0, 0, 0, 0, 0))
    e.spawn_sdf("marker", MARKER, (0.0, 0.0, 0.3, 0, 0, 0))  # rests on the robot's top
    e.advance(0.5)
    before = relative(e, "robot", "marker")
    e.attacher.attach(e, "robot", "base_link", "marker", "link")
    assert ("robot", "base_link", "marker", "link") not in e.attacher.joints  # queued
    run(e, r, [(0.3, 0.0, 1.0), (0.2, 0.5, 1.0)])
    assert e.model_pose("robot")[0][0] > 0.3
    # same relative pose, expressed in the robot frame (it turned)
    pr, qr = e.model_pose("robot")
    pm, _ = e.model_pose("marker")
    from fleetsim.sim.build import rpy_from_quat

    yaw = rpy_from_quat(qr)[2]
    c, s = np.cos(yaw), np.sin(yaw)
    local = np.array([[c, s], [-s, c]]) @ (pm - pr)[:2]
    np.testing.assert_allclose(local, before[:2], atol=0.01)
    e.attacher.detach(e, "robot", "base_link", "marker", "link")
    e.advance(0.1)
    dropped = e.model_pose("marker")[0].copy()
    e.set_model_state(
        "marker",
        position=[dropped[0], dropped[1] + 2.0, 0.01],
        linear=[0, 0, 0],
        angular=[0, 0, 0],
        orientation=[1, 0, 0, 0],
    )
    run(e, r, [(0.3, 0.0, 1.0)])
    assert np.linalg.norm(e.model_pose("marker")[0][:2] - [dropped[0], dropped[1] + 2.0]) < 0.01


def test_attach_errors(diffbot):
    e = Engine(None)
    e.spawn_robot("robot", diffbot)
    with pytest.raises(SimulationError, match="model 'robot' has no link 'gripper'"):
        e.attacher.attach(e, "robot", "gripper", "robot", "base_link")
    with pytest.raises(SimulationError, match="are not attached"):
        e.attacher.detach(e, "robot", "base_link", "ground_plane", "link")
