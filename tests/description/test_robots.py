"""Every shipped robot package: loads, passes `urdf check`, has physical inertias and the
Gazebo plugins the simulator drives; the hunter matches the manual's check_urdf tree."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from fleetsim.description.packages import ASSET_ROBOTS
from fleetsim.description.srdf import load_srdf
from fleetsim.description.tree import check_report
from fleetsim.description.urdf import load_robot, parse_urdf

ROBOTS = ["hunter", "lizi", "pioneer3at", "turtlebot3_burger", "turtlebot3_waffle", "jackal"]

HUNTER_GOLDEN = """\
robot name is: robocluedo_robot
---------- Successfully Parsed XML ---------------
root Link: base_link has 9 child(ren)
    child(1):  arm_base_link
        child(1):  arm_link_01
            child(1):  arm_link_02
                child(1):  arm_link_03
                    child(1):  cluedo_link
                    child(2):  camera_arm
    child(2):  link_a_left_wheel
    child(3):  link_a_right_wheel
    child(4):  camera_front_low
    child(5):  camera_left
    child(6):  camera_right
    child(7):  laser
    child(8):  link_left_wheel
    child(9):  link_right_wheel
"""


def top_file(name: str) -> Path:
    return ASSET_ROBOTS / name / "urdf" / f"{name}.urdf.xacro"


@pytest.fixture(scope="module")
def robots():
    return {name: load_robot(top_file(name)) for name in ROBOTS}


def test_hunter_tree_matches_the_manual(robots):
    assert check_report(robots["hunter"]) == HUNTER_GOLDEN


@pytest.mark.parametrize("name", ROBOTS)
def test_robot_is_a_valid_tree_with_physical_inertias(robots, name):
    r = robots[name]
    assert (ASSET_ROBOTS / name / "package.xml").is_file()
    check_report(r)  # raises if the tree is not valid
    for link in r.links.values():
        if link.inertial is None:
            assert not link.collisions, f"{name}: {link.name} collides but has no inertia"
            continue
        i = link.inertial
        tensor = np.array([[i.ixx, i.ixy, i.ixz], [i.ixy, i.iyy, i.iyz], [i.ixz, i.iyz, i.izz]])
        eig = np.linalg.eigvalsh(tensor)
        assert i.mass > 0 and eig.min() > 0, f"{name}: {link.name}"
        # triangle inequality of principal moments (a real rigid body)
        assert eig[0] + eig[1] >= eig[2] * (1 - 1e-9), f"{name}: {link.name}"
    # export round-trips through plain URDF
    again = parse_urdf(r.to_urdf())
    assert again.links == r.links and again.joints == r.joints


def _plugin(robot, filename):
    found = [p for p in robot.plugins() if p.filename == filename]
    found += [p for s in robot.sensors() for p in s.plugins if p.filename == filename]
    assert found, f"{robot.name} has no {filename}"
    return found[0]


@pytest.mark.parametrize(
    ("name", "diameter", "separation"),
    [("lizi", 0.154, 0.255), ("pioneer3at", 0.215, 0.394), ("jackal", 0.196, 0.37559)],
)
def test_skid_steer_robots(robots, name, diameter, separation):
    r = robots[name]
    p = _plugin(r, "libgazebo_ros_skid_steer_drive.so").params
    assert float(p["wheelDiameter"]) == pytest.approx(diameter)
    assert float(p["wheelSeparation"]) == pytest.approx(separation)
    assert p["commandTopic"] == "cmd_vel" and p["odometryTopic"] == "odom"
    for key in ("leftFrontJoint", "rightFrontJoint", "leftRearJoint", "rightRearJoint"):
        joint = r.joints[p[key]]
        assert joint.type == "continuous"
        wheel = r.links[joint.child]
        radius = wheel.collisions[0].geometry.radius
        assert 2 * radius == pytest.approx(diameter)
        assert abs(joint.origin.xyz[1]) == pytest.approx(separation / 2)
        mu = [float(g.properties["mu1"]) for g in r.gazebo_for(wheel.name) if "mu1" in g.properties]
        assert mu and mu[0] >= 0.8


def test_lizi_laser_and_ground_truth(robots):
    r = robots["lizi"]
    laser = _plugin(r, "libgazebo_ros_laser.so").params
    assert laser["topicName"] == "base_scan" and laser["frameName"] == "laser_link"
    p3d = _plugin(r, "libgazebo_ros_p3d.so").params
    assert p3d["topicName"] == "base_pose_ground_truth" and p3d["bodyName"] == "base_link"
    assert r.sensors()[0].pose.xyz == (0.0, 0.0, 1.0)  # matches the lesson's static tf


def test_jackal_front_laser(robots):
    (scan,) = [s for s in robots["jackal"].sensors() if s.type == "ray"]
    h = scan.ray["scan"]["horizontal"]
    assert int(h["samples"]) == 720
    assert float(h["max_angle"]) - float(h["min_angle"]) == pytest.approx(np.radians(270), 1e-4)
    assert float(scan.ray["range"]["max"]) == 10.0
    link = robots["jackal"].links["base_link"].collisions[0].geometry
    assert link.size[0] == pytest.approx(0.508)
    width = 2 * robots["jackal"].joints["front_left_wheel"].origin.xyz[1] + 0.05
    assert width == pytest.approx(0.43, abs=0.005)


@pytest.mark.parametrize(
    ("name", "sep"), [("turtlebot3_burger", 0.160), ("turtlebot3_waffle", 0.287)]
)
def test_turtlebots_diff_drive_and_360_laser(robots, name, sep):
    r = robots[name]
    p = _plugin(r, "libgazebo_ros_diff_drive.so").params
    assert float(p["wheelSeparation"]) == pytest.approx(sep)
    assert float(p["wheelDiameter"]) == pytest.approx(0.066)
    assert p["leftJoint"] in r.joints and p["rightJoint"] in r.joints
    (laser,) = [s for s in r.sensors() if s.type == "ray"]
    h = laser.ray["scan"]["horizontal"]
    assert float(h["max_angle"]) - float(h["min_angle"]) == pytest.approx(2 * np.pi, 1e-4)
    assert laser.plugins[0].params["topicName"] == "scan"


def test_waffle_rgbd_camera(robots):
    (cam,) = [s for s in robots["turtlebot3_waffle"].sensors() if s.type == "depth"]
    p = cam.plugins[0]
    assert p.filename == "libgazebo_ros_openni_kinect.so"
    topics = {
        p.params["cameraName"] + "/" + p.params[k]
        for k in ("imageTopicName", "cameraInfoTopicName", "depthImageTopicName")
    }
    assert topics == {"camera/rgb/image_raw", "camera/rgb/camera_info", "camera/depth/image_raw"}
    assert p.params["frameName"] in robots["turtlebot3_waffle"].links
    assert cam.camera["image"]["width"] == "640"


def test_hunter_sensors_plugins_and_transmissions(robots):
    r = robots["hunter"]
    cams = {s.reference: s for s in r.sensors() if s.type == "camera"}
    assert set(cams) == {"camera_front_low", "camera_left", "camera_right", "camera_arm"}
    assert cams["camera_arm"].plugins[0].params["cameraName"] == "robocluedo_robot/camera_arm"
    assert _plugin(r, "libgazebo_ros_laser.so").params["topicName"] == "/scan"
    dd = _plugin(r, "libgazebo_ros_diff_drive.so").params
    assert (dd["leftJoint"], dd["rightJoint"]) == ("joint_left_wheel", "joint_right_wheel")
    assert "robotNamespace" in _plugin(r, "libgazebo_ros_control.so").params
    assert [t.joints for t in r.transmissions] == [
        [(f"arm_joint_0{i}", "hardware_interface/EffortJointInterface")] for i in range(1, 5)
    ]
    assert r.joints["arm_joint_04"].child == "cluedo_link"
    relaid = load_robot(top_file("hunter"), args={"laser_topic": "scan"})
    assert _plugin(relaid, "libgazebo_ros_laser.so").params["topicName"] == "scan"


def test_hunter_srdf_and_controller_config(robots):
    r = robots["hunter"]
    cfg = ASSET_ROBOTS / "hunter" / "config"
    srdf = load_srdf(cfg / "robocluedo_robot.srdf", r)
    arm = [f"arm_joint_0{i}" for i in range(1, 5)]
    # the chain starts at base_link, so it holds the fixed arm_base_to_base too (as MoveIt's
    # joint model group does; its active joints are the four arm joints)
    assert srdf.group_joints("arm_group", r) == ["arm_base_to_base", *arm]
    assert srdf.group_states[("arm_group", "home")] == dict(
        zip(arm, [-1.57, 0.1293, -0.4276, 0.3481], strict=True)
    )
    assert len([k for k in srdf.group_states if k[0] == "arm_group"]) == 9
    ctrl = yaml.safe_load((cfg / "ros_controllers.yaml").read_text())
    c = ctrl["arm_group_controller"]
    assert c["type"] == "effort_controllers/JointTrajectoryController"
    assert c["joints"] == arm and all(c["gains"][j]["p"] > 0 for j in arm)
    assert ctrl["joint_state_controller"]["publish_rate"] == 50
    limits = yaml.safe_load((cfg / "joint_limits.yaml").read_text())
    assert limits["default_velocity_scaling_factor"] == 1
    assert limits["default_acceleration_scaling_factor"] == 1
    assert [limits["joint_limits"][j]["max_velocity"] for j in arm] == [0.2, 0.2, 0.2, 0.5]
