"""Robot discovery from frames and footprints from costmap parameters."""

from __future__ import annotations

import numpy as np

from fleetsim.viz.robots import (
    DEFAULT_ROBOT_RADIUS,
    circle_footprint,
    colour_of,
    footprint_from_params,
    robot_of_frame,
    robot_of_topic,
)


def test_robot_names():
    assert robot_of_frame("lizi1/base_link") == "lizi1"
    assert robot_of_frame("/lizi2/base_footprint") == "lizi2"
    assert robot_of_frame("base_link") == ""
    assert robot_of_frame("lizi1/odom") is None
    assert robot_of_topic("/lizi1/move_base/goal") == "lizi1" and robot_of_topic("/map") == ""


def test_footprint_sources_in_order():
    square = [[0.2, 0.2], [0.2, -0.2], [-0.2, -0.2], [-0.2, 0.2]]
    params = {
        "a": {"move_base": {"local_costmap": {"footprint": square}}},
        "b": {"move_base": {"global_costmap": {"footprint": str(square)}}},  # a string, as ROS
        "c": {"move_base": {"robot_radius": 0.3}},
        "d": {"move_base": {"local_costmap": {"footprint": [[1, 2]]}}},  # invalid: 1 point
    }
    np.testing.assert_allclose(footprint_from_params(params, "a"), square)
    np.testing.assert_allclose(footprint_from_params(params, "b"), square)
    assert np.allclose(np.hypot(*footprint_from_params(params, "c").T), 0.3)
    default = footprint_from_params(params, "d")
    assert np.allclose(np.hypot(*default.T), DEFAULT_ROBOT_RADIUS)
    assert footprint_from_params({}, "").shape == circle_footprint(1.0).shape


def test_colours_cycle():
    assert colour_of(0) == colour_of(10) != colour_of(1)


def test_a_robot_without_move_base_is_drawn_by_its_collision_shapes():
    """The tutorial's leader (a burger driven by cmd_vel, no move_base) had been drawn as
    costmap_2d's default 0.92 m disc; its URDF's collision shapes give 0.14 x 0.18 m. A
    costmap footprint still comes first; a URDF that does not parse leaves the default."""
    from fleetsim.description import load_robot
    from fleetsim.description.packages import ASSET_ROBOTS

    burger = load_robot(
        ASSET_ROBOTS / "turtlebot3_burger" / "urdf" / "turtlebot3_burger.urdf.xacro"
    )
    params = {"karl": {"robot_description": burger.to_urdf()}}
    fp = footprint_from_params(params, "karl")
    size = fp.max(axis=0) - fp.min(axis=0)
    np.testing.assert_allclose(size, [0.140, 0.178], atol=0.005)
    params["karl"]["move_base"] = {"robot_radius": 0.1}
    assert np.allclose(np.hypot(*footprint_from_params(params, "karl").T), 0.1)
    broken = {"x": {"robot_description": "<robot name='x'><link name="}}
    assert np.allclose(np.hypot(*footprint_from_params(broken, "x").T), DEFAULT_ROBOT_RADIUS)
