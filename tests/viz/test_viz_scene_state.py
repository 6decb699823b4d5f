"""SceneState: latest-tf lookups, scans and robots placed in the fixed frame."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.record import BagReader
from fleetsim.viz.scene_state import LatestTf, SceneState

coord = st.floats(-10, 10)
angle = st.floats(-np.pi, np.pi)


@settings(max_examples=50, deadline=None)
@given(coord, coord, angle, coord, coord, angle)
def test_lookup_composes_and_inverts(x1, y1, a1, x2, y2, a2):
    tf = LatestTf()
    tf.set("map", "odom", (x1, y1, 0), (0, 0, np.sin(a1 / 2), np.cos(a1 / 2)))
    tf.set("odom", "base", (x2, y2, 0), (0, 0, np.sin(a2 / 2), np.cos(a2 / 2)))
    m = tf.lookup("map", "base")
    expected = np.array(
        [x1 + np.cos(a1) * x2 - np.sin(a1) * y2, y1 + np.sin(a1) * x2 + np.cos(a1) * y2]
    )
    np.testing.assert_allclose(m[:2, 3], expected, atol=1e-9)
    np.testing.assert_allclose(tf.lookup("base", "map") @ m, np.eye(4), atol=1e-9)
    assert tf.lookup("map", "elsewhere") is None


def test_scene_from_recording(room_recording):
    path, duration = room_recording
    reader = BagReader(path)
    state = SceneState("map", reader.params())
    for m in reader.messages():
        state.handle(m.topic, m.typename, m.msg, m.log_time_ns)
    snap = state.snapshot()
    assert [r.name for r in snap.robots] == ["robot0", "robot1"]
    x_end = 2.0 + 0.5 * duration  # run(4.0) includes the events at t = 4.0
    np.testing.assert_allclose(snap.robots[0].pose, [x_end, 2.0, 0.0], atol=1e-9)
    # robot0's footprint parameter, placed at its pose
    np.testing.assert_allclose(snap.robots[0].outline.min(axis=0), [x_end - 0.3, 1.8], atol=1e-9)
    # every laser point lies on a wall face of the room
    pts = snap.scans["robot0"]
    on_wall = (np.abs(pts[:, 0] - 9.85) < 1e-3) | (np.abs(pts[:, 1] - 7.85) < 1e-3)
    on_wall |= np.abs(pts[:, 1] - 0.15) < 1e-3
    assert pts.shape[0] > 100 and on_wall.all()
    np.testing.assert_allclose(snap.goals["robot1"], [8.0, 6.0, 0.0])
    assert snap.paths["/robot0/move_base/NavfnROS/plan"][-1].tolist() == [8.0, 2.0]
    assert snap.particles["/robot1/particlecloud"].shape == (30, 3)
    assert snap.robots[1].trail[0, 0] < 2.1 and snap.robots[1].trail.shape[0] > 10
    assert state.bounds() == (0.0, 200 * np.float32(0.05), 0.0, 160 * np.float32(0.05))


def test_a_plan_in_odom_stays_where_it_was_planned_when_odom_drifts():
    from fleetsim.msgs import geometry_msgs, nav_msgs, tf2_msgs
    from fleetsim.tf._msgs import make_transform_stamped

    def tf(x):
        return tf2_msgs.TFMessage(
            transforms=[make_transform_stamped("map", "r/odom", 0.0, (x, 0, 0))]
        )

    state = SceneState("map")
    state.handle("/tf", "tf2_msgs/msg/TFMessage", tf(1.0), 1)
    plan = nav_msgs.Path()
    plan.header.frame_id = "r/odom"
    pose = geometry_msgs.PoseStamped()
    pose.pose.position.x = 2.0
    plan.poses = [pose]
    state.handle("/r/plan", "nav_msgs/msg/Path", plan, 2)
    state.handle("/tf", "tf2_msgs/msg/TFMessage", tf(1.5), 3)  # amcl corrects the drift
    assert state.snapshot().paths["/r/plan"].tolist() == [[3.0, 0.0]]
    orphan = SceneState("map")  # no tf yet: placed once its frame connects
    orphan.handle("/r/plan", "nav_msgs/msg/Path", plan, 1)
    orphan.handle("/tf", "tf2_msgs/msg/TFMessage", tf(0.5), 2)
    assert orphan.snapshot().paths["/r/plan"].tolist() == [[2.5, 0.0]]
