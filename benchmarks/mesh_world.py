"""A Gazebo mesh world: Gazebo's ``model://willowgarage`` (a 13,348-triangle COLLADA building).

Prints the convex decomposition (components, rule per component, parts, time), the world build
time without and with the disk cache, contacts of robots spawned in free space at the first
steps (a building colliding as one hull pins them all), and the laser sweep of all robots
(best of ``--repeats``) with the worst difference from an exact ray/triangle intersection.
Needs Gazebo's model folder (``gazebo_models/willowgarage``); the world includes it with the
lesson's ``<pose>-3 54 0 0 0 30</pose>`` (30 rad).
Usage: python benchmarks/mesh_world.py /path/to/gazebo_models [--robots 100] [--repeats 20]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import mujoco
import numpy as np

from fleetsim.description import load_robot
from fleetsim.sim import Engine, decompose
from fleetsim.sim.mesh_assets import HULL_GROUP
from fleetsim.sim.mesh_files import triangle_mesh
from fleetsim.sim.plugins.laser import LaserPlugin

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from sim.ray_triangle import first_hit, horizontal

BURGER = (
    Path(__file__).resolve().parents[1]
    / "src/fleetsim/assets/robots/turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
)
POSE = (-3.0, 54.0, 0.0, 0.0, 0.0, 30.0)


def free_points(engine, n, rng, lo, hi):
    """World points 0.4 m clear of the building's collision parts (8 rays at 0.1 m)."""
    yaw = POSE[5]
    rot = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
    mask = np.zeros(6, np.uint8)
    mask[HULL_GROUP] = 1
    gid = np.zeros(1, np.int32)
    out = []
    while len(out) < n:
        p = rot @ rng.uniform(lo, hi) + POSE[:2]
        clear = all(
            not 0 <= mujoco.mj_ray(
                engine.model, engine.data, np.array([*p, 0.1]),
                np.array([np.cos(a), np.sin(a), 0.0]), mask, 1, -1, gid,
            ) < 0.4
            for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)
        )  # fmt: skip
        if clear:
            out.append(p)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("models", type=Path, help="folder holding willowgarage/")
    ap.add_argument("--robots", type=int, default=100)
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args()
    os.environ["GAZEBO_MODEL_PATH"] = str(args.models)
    tmp = Path(tempfile.mkdtemp())
    os.environ["FLEETSIM_CACHE_DIR"] = str(tmp / "cache")
    dae = args.models / "willowgarage/meshes/willowgarage_collision.dae"
    v, f = triangle_mesh(dae)
    t0 = time.perf_counter()
    d = decompose.decompose(v, f)
    took = time.perf_counter() - t0
    rules = {m: d.methods.count(m) for m in dict.fromkeys(d.methods)}
    print(f"mesh: {len(f)} triangles; {len(d.methods)} components {rules}; {len(d.parts)} parts")
    print(f"decomposition: {took:.2f} s; problems: {d.problems or 'none'}")
    world = tmp / "willow.world"
    world.write_text(
        "<sdf version='1.6'><world name='w'><include><uri>model://ground_plane</uri></include>"
        "<include><uri>model://willowgarage</uri><pose>" + " ".join(map(str, POSE)) + "</pose>"
        "</include></world></sdf>"
    )
    for label in ("first build (decomposes)", "second build (disk cache)"):
        t0 = time.perf_counter()
        engine = Engine(world)
        print(f"{label}: {time.perf_counter() - t0:.2f} s")
    rng = np.random.default_rng(0)
    robot = load_robot(BURGER)
    points = free_points(engine, args.robots, rng, (1.0, 1.0), (57.0, 44.0))
    entries = engine.spawn_robots(
        [(f"r{i}", robot, (*p, 0.0, 0.0, 0.0, 0.0)) for i, p in enumerate(points)]
    )
    engine.advance(0.1)
    touching = [c for c in engine.contacts() if "willowgarage" in (c.model1, c.model2)]
    print(f"{args.robots} robots, contacts with the building after 0.1 s: {len(touching)}")
    lasers = [p for e in entries for p in e.plugins if isinstance(p, LaserPlugin)]
    for lz in lasers:
        lz.noise_std = lz.noise_mean = 0.0
    engine.layouts.clear()
    engine.lasers.measure(engine, lasers, engine.time)  # compile the kernels
    best = np.inf
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        readings = engine.lasers.measure(engine, lasers, engine.time)
        best = min(best, time.perf_counter() - t0)
    beams = sum(lz.samples for lz in lasers)
    print(f"laser sweep, {len(lasers)} lasers x {beams // len(lasers)} beams: {best * 1e3:.1f} ms")
    wv, wf = decompose.weld(v, f)
    rot = np.array(
        [[np.cos(POSE[5]), -np.sin(POSE[5]), 0], [np.sin(POSE[5]), np.cos(POSE[5]), 0], [0, 0, 1]]
    )
    wv = wv @ rot.T + POSE[:3]
    tris = wv[wf]
    worst = 0.0
    for lz, reading in list(zip(lasers, readings))[:10]:
        origins, angles, _ = lz.rays(engine)
        for g, ang in zip(reading.ranges, angles):
            ex = first_hit(tris, origins[0], horizontal(ang), lz.range_min, lz.range_max)
            if np.isfinite(g) and g < ex - 1e-3:
                continue  # another robot in the way
            if np.isfinite(g) and np.isfinite(ex):
                worst = max(worst, abs(g - ex))
            elif np.isfinite(g) != np.isfinite(ex):
                worst = np.inf
    print(f"laser vs exact ray/triangle, 10 lasers: worst {worst * 1e3:.3f} mm")
    # the collision parts (what robots touch) against the true triangles at robot heights
    mask = np.zeros(6, np.uint8)
    mask[HULL_GROUP] = 1
    gid = np.zeros(1, np.int32)
    errors = []
    for p in points[:20]:
        for z in (0.05, 0.3, 1.0):
            origin = np.array([*p, z])
            for ang in np.linspace(0, 2 * np.pi, 90, endpoint=False):
                vec = np.array([np.cos(ang), np.sin(ang), 0.0])
                got = mujoco.mj_ray(engine.model, engine.data, origin, vec, mask, 1, -1, gid)
                ex = first_hit(tris, origin, vec, 0.0, 10.0)
                if np.isfinite(ex) and 0 <= got <= 10.0:
                    errors.append(abs(got - ex))
                elif np.isfinite(ex) != (0 <= got <= 10.0):
                    errors.append(np.inf)
    errors = np.array(errors)
    print(
        f"collision parts vs true triangles, {len(errors)} rays at 0.05/0.3/1.0 m: "
        f"median {np.median(errors) * 1e3:.3f} mm, 99% {np.quantile(errors, 0.99) * 1e3:.2f} mm, "
        f"worst {errors.max() * 1e3:.2f} mm"
    )


if __name__ == "__main__":
    main()
