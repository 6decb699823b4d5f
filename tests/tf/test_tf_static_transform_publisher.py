"""static_transform_publisher: ROS 1 tf and tf2_ros argument forms, tf_prefix, publishing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fleetsim.errors import ConnectivityError, ParameterError
from fleetsim.runtime import Runtime
from fleetsim.tf import StaticTransformPublisher
from fleetsim.tf.static_transform_publisher import static_transform_from_args
from fleetsim.tf.transforms import quaternion_from_euler


def test_tf_euler_form_with_period():
    s = static_transform_from_args("0 0 1 0.5 0 0 base_link laser_link 100")
    assert s.translation == (0.0, 0.0, 1.0)
    assert np.allclose(s.rotation, quaternion_from_euler(0.0, 0.0, 0.5))  # yaw first in args
    assert (s.frame_id, s.child_frame_id, s.period) == ("base_link", "laser_link", 0.1)


def test_argument_order_is_yaw_pitch_roll():
    s = static_transform_from_args(["0", "0", "0", "0.1", "0.2", "0.3", "a", "b"])
    assert np.allclose(s.rotation, quaternion_from_euler(0.3, 0.2, 0.1))
    assert s.period is None


def test_quaternion_forms_and_normalisation():
    s = static_transform_from_args(["1", "2", "3", "0", "0", "0", "2", "map", "odom", "50"])
    assert s.rotation == (0.0, 0.0, 0.0, 1.0) and s.period == 0.05
    s = static_transform_from_args("1 2 3 0 0 0.7071068 0.7071068 map odom")
    assert s.period is None and s.child_frame_id == "odom"
    assert math.isclose(s.rotation[2], math.sqrt(0.5), rel_tol=1e-6)


def test_ros2_flag_form():
    s = static_transform_from_args(
        ["--x", "1", "--yaw", "1.57", "--frame-id", "map", "--child-frame-id", "odom"]
    )
    assert s.translation == (1.0, 0.0, 0.0) and s.period is None
    assert np.allclose(s.rotation, quaternion_from_euler(0, 0, 1.57))
    s = static_transform_from_args("--qw 1 --qz 1 --frame_id map --child_frame_id odom")
    assert np.allclose(s.rotation, [0, 0, math.sqrt(0.5), math.sqrt(0.5)])


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ("0 0 1 0 0 base laser", r"expected 8, 9 or 10 arguments, got 7"),
        (
            "0 0 one 0 0 0 base laser 100",
            r"argument 'z' \(3 of 9\) must be a finite number, got 'one'",
        ),
        ("0 0 1 0 0 0 base laser 0", r"'period_in_ms' must be > 0 .* got '0'"),
        ("0 0 1 0 0 0 0 base laser 100", r"quaternion \(0.0, 0.0, 0.0, 0.0\) has zero length"),
        ("0 0 1 0 0 0 1 2 3", r"9 arguments are either"),
        ("0 0 1 0 0 0 base /base 100", r"frame_id and child_frame_id are both 'base'"),
        ("0 0 1 nan 0 0 base laser", r"argument 'yaw' \(4 of 8\) must be a finite number"),
        ("--x 1 --frame-id map", r"--frame-id and --child-frame-id are required"),
        ("--x 1 --bogus 2 --frame-id a --child-frame-id b", r"unknown flag '--bogus'"),
        ("--qw 1 --yaw 1 --frame-id a --child-frame-id b", r"not both"),
        ("--x", r"expected '--name value' pairs"),
    ],
)
def test_bad_arguments_name_the_argument(args, message):
    with pytest.raises(ParameterError, match=message):
        static_transform_from_args(args.split())


def test_periodic_form_publishes_on_tf_post_dated_under_tf_prefix():
    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    buf = rt.tf_buffer
    node = StaticTransformPublisher(
        rt,
        "laser_link_broadcaster",
        "/lizi1",
        args=["0", "0", "1", "0", "0", "0", "lizi1/base_link", "laser_link", "100"],
    )
    assert (node.frame_id, node.child_frame_id) == ("lizi1/base_link", "lizi1/laser_link")
    rt.run(duration=1.0)
    info = buf.frame_info("lizi1/laser_link")
    assert not info.is_static and info.rate == pytest.approx(10.0)
    assert info.most_recent == pytest.approx(1.1)  # published at 1.0, stamped a period ahead
    assert buf.lookup_tuple("lizi1/base_link", "lizi1/laser_link", rt.now())[2] == 1.0
    assert rt.graph.topics["/tf"].publishers and not rt.graph.topics["/tf_static"].publishers


def test_tf2_form_latches_on_tf_static():
    rt = Runtime()
    StaticTransformPublisher(rt, "map_to_odom", args=["1", "2", "0", "0", "0", "0", "/map", "odom"])
    rt.run(duration=0.5)
    buf = rt.tf_buffer  # subscribes after the publication: latching delivers it
    rt.spin_once()
    assert buf.frame_info("odom").is_static
    assert buf.lookup_tuple("map", "odom", 99.0)[:2] == (1.0, 2.0)


def test_three_prefixed_robots_get_separate_trees_joined_by_map():
    """The seeds' multi-robot launch: one laser publisher per robot group, shared /tf."""
    rt = Runtime()
    buf = rt.tf_buffer
    for name in ("lizi1", "lizi2", "lizi3"):
        rt.params.set(f"/{name}/tf_prefix", name)
        StaticTransformPublisher(
            rt,
            "laser_link_broadcaster",
            f"/{name}",
            args=f"0 0 1 0 0 0 {name}/base_link {name}/laser_link 100".split(),
        )
        StaticTransformPublisher(rt, "odom_bc", f"/{name}", args="0 0 0 0 0 0 odom base_link 100")
    rt.run(duration=0.35)
    assert buf.parents() == {
        f"{n}/{child}": f"{n}/{parent}"
        for n in ("lizi1", "lizi2", "lizi3")
        for parent, child in (("odom", "base_link"), ("base_link", "laser_link"))
    }
    with pytest.raises(
        ConnectivityError, match=r"under root 'lizi1/odom'.*under root 'lizi2/odom'"
    ):
        buf.lookup_transform("lizi1/laser_link", "lizi2/laser_link")
    for i, name in enumerate(("lizi1", "lizi2", "lizi3")):  # localization joins them under map
        StaticTransformPublisher(
            rt, "map_bc", f"/{name}", args=f"{20 + 2 * i} 15 0 0 0 0 /map odom".split()
        )
    rt.run(duration=0.1)
    x, y, _ = buf.lookup_pose2d("lizi1/laser_link", "lizi3/laser_link")
    assert (x, y) == pytest.approx((4.0, 0.0))
