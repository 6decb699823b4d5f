"""Skid steer: straight runs track the truth, turning slips and odometry drifts."""

import numpy as np

from fleetsim.sim import Engine

from .test_diff_drive import last, run, yaw_of


def test_skid_steer_odometry_drifts_when_turning(skidbot):
    e = Engine(None)
    r = e.spawn_robot("jackal", skidbot, (0, 0, 0.1, 0, 0, 0))
    assert [type(p).__name__ for p in r.plugins] == ["SkidSteerPlugin", "P3dPlugin"]
    readings = run(e, r, [(0.5, 0.0, 2.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    assert odom.child_frame_id == "jackal/base_link" and odom.publish_tf
    assert truth.position[0] > 0.8
    assert abs(odom.position[0] - truth.position[0]) < 0.05 * truth.position[0]
    readings = run(e, r, [(0.2, 0.8, 3.0)])
    odom, truth = last(readings, "odom"), last(readings, "base_pose_ground_truth")
    turned_truth = yaw_of(truth.orientation)
    turned_odom = yaw_of(odom.orientation)
    assert turned_truth > 0.15  # it does turn
    assert abs(turned_odom - turned_truth) > 0.2  # but the wheels slip: odometry drifts
    assert np.linalg.norm(odom.position[:2] - truth.position[:2]) > 0.02
