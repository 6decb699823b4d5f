"""Cameras render only while their images have subscribers, as gazebo_ros_camera does."""

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
