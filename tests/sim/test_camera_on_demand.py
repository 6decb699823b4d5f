"""Cameras render only while their images have subscribers, as gazebo_ros_camera does."""

import numpy as np

from fleetsim.description import load_robot
from fleetsim.msgs import sensor_msgs
from fleetsim.runtime import Runtime
from fleetsim.sim.node import Simulator
from fleetsim.sim.plugins.camera import CameraPlugin

WAFFLE = "src/fleetsim/assets/robots/turtlebot3_waffle/urdf/turtlebot3_waffle.urdf.xacro"


def test_images_only_while_subscribed():
    rt = Runtime()
    sim = Simulator(rt, "gazebo")
    entry = sim.spawn_robot("tb", load_robot(WAFFLE), namespace="/tb")
    cam = next(p for p in entry.plugins if isinstance(p, CameraPlugin))
    renders = []
    original = cam.render
    cam.render = lambda engine, depth=False: renders.append(depth) or original(engine, depth)
    rt.run(duration=0.5)
    assert renders == []
    images = []
    rt.graph.subscribe("/tb/camera/rgb/image_raw", sensor_msgs.Image, images.append)
    rt.run(duration=0.5)
    assert images and images[-1].height == cam.height and renders


def test_depth_camera_publishes_a_point_cloud_while_subscribed():
    from fleetsim.nav.costmap.costmap_ros import points_from_cloud2

    from .plugins.test_camera import camera_robot, red_wall_world

    rt = Runtime()
    sim = Simulator(rt, "gazebo")
    sim.engine.spawn_sdf("wall", red_wall_world().models[1])
    sim.spawn_robot("r", camera_robot("depth", "libgazebo_ros_openni_kinect.so"))
    clouds = []
    rt.graph.subscribe("/r/front_camera/points", sensor_msgs.PointCloud2, clouds.append)
    rt.run(duration=0.5)
    assert len(clouds) >= 2
    cloud = clouds[-1]
    assert cloud.header.frame_id == "r/camera_optical" and (cloud.height, cloud.width) == (48, 64)
    pts = points_from_cloud2(cloud)
    # the wall face 1.85 m ahead along the optical z axis, spread left-right (x) and up-down (y)
    assert abs(float(np.median(pts[:, 2])) - 1.85) < 0.02
    assert pts[:, 0].min() < -0.5 < 0.5 < pts[:, 0].max() and pts[:, 1].min() < 0 < pts[:, 1].max()
