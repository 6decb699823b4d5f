"""Camera frames per second on the CPU (MuJoCo EGL, software rendering without a GPU).

One robot with a 320 x 240 RGB camera in the warehouse demo world; prints RGB and depth frames
per second and the time per frame including the copy out of the renderer.
Usage: python benchmarks/camera_fps.py [--frames 100] [--width 320] [--height 240]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")

from fleetsim.description import parse_urdf
from fleetsim.sim import Engine

ROOT = Path(__file__).resolve().parent.parent
WORLD = ROOT / "src" / "fleetsim" / "assets" / "worlds" / "warehouse.world"
ROBOT = ROOT / "tests" / "sim" / "fixtures" / "diffbot.urdf"
CAMERA = """
  <gazebo reference="laser_link">
    <sensor type="depth" name="cam">
      <update_rate>30</update_rate>
      <camera><horizontal_fov>1.047</horizontal_fov>
        <image><width>{w}</width><height>{h}</height><format>R8G8B8</format></image>
        <clip><near>0.05</near><far>50</far></clip></camera>
      <plugin name="camera" filename="libgazebo_ros_openni_kinect.so">
        <cameraName>camera</cameraName><frameName>camera_link</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--frames", type=int, default=100)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    args = ap.parse_args()
    text = ROBOT.read_text().replace("</robot>", CAMERA.format(w=args.width, h=args.height))
    engine = Engine(WORLD)
    entry = engine.spawn_robot("bot", parse_urdf(text), (-1.0, 0.0, 0.0, 0.0, 0.0, 0.3))
    cam = next(p for p in entry.plugins if p.name == "camera")
    cam.render(engine)  # create the GL context
    for depth in (False, True):
        t0 = time.perf_counter()
        for _ in range(args.frames):
            cam.render(engine, depth=depth)
        dt = (time.perf_counter() - t0) / args.frames
        kind = "depth" if depth else "RGB"
        print(
            f"{kind:>5} {args.width}x{args.height}: {1 / dt:7.1f} frames/s "
            f"({1e3 * dt:.2f} ms per frame)"
        )
    t0 = time.perf_counter()
    for _ in range(args.frames // 4):
        engine.advance(1 / 30)  # physics + a 30 Hz RGB-D reading
    dt = (time.perf_counter() - t0) / (args.frames // 4)
    print(f"simulated RGB-D camera at 30 Hz: {1 / dt:.1f} sim frames per wall second")


if __name__ == "__main__":
    main()
