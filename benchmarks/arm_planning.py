"""The hunter's arm through move_group (issue 16): planning and IK times, execution error.

For each of the nine named poses of the hunter's SRDF, from every other pose: the median wall
time of a planning request (collision checks in MuJoCo, toppra timing; target <= 20 ms), and
how many of those requests needed OMPL (RRTConnect) with their own median: a request whose
straight joint-space motion is collision-free returns that line without running a planner;
the median time of OMPL's RRTConnect on the same requests with that shortcut off (the path
alone, as MoveIt would always plan it);
the median time of a position-only IK solve for each pose's cluedo_link position (target
<= 5 ms); then each pose reached in the simulator through move_group and the controllers
(ros_controllers.yaml: P = 10 plus i = 20), with the largest joint error at rest.

Usage: python benchmarks/arm_planning.py [--repeats 5]
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from fleetsim.description import load_robot
from fleetsim.description.packages import ASSET_ROBOTS
from fleetsim.moveit import MoveGroupCommander
from fleetsim.moveit.planner import plan_path
from fleetsim.msgs import moveit_msgs
from moveit.conftest import Hunters


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    h = Hunters(load_robot(ASSET_ROBOTS / "hunter" / "urdf" / "hunter.urdf.xacro"))
    mg = h.move_group("hunter1")
    model = mg.model
    poses = model.named_targets("arm_group")
    ctx = mg.pipeline.context("arm_group")
    print(
        f"{'pose':<14} {'plan ms (median)':>17} {'OMPL runs':>10} {'OMPL ms':>8} {'forced':>7} "
        f"{'IK ms (median)':>15} {'exec error rad':>15}"
    )
    plan_all, ik_all, ompl_all, forced_all = [], [], [], []
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=h.rt)
    for name, goal in poses.items():
        plans, ompl, forced = [], [], []
        for start_name, start in poses.items():
            if start_name == name:
                continue
            for _ in range(args.repeats):
                req = moveit_msgs.MotionPlanRequest(group_name="arm_group", allowed_planning_time=5)
                req.planner_id = "RRTConnect"
                req.goal_constraints = [
                    moveit_msgs.Constraints(
                        joint_constraints=[
                            moveit_msgs.JointConstraint(joint_name=j, position=float(v))
                            for j, v in zip(ctx.joints, goal, strict=True)
                        ]
                    )
                ]
                t0 = time.perf_counter()
                res = mg.pipeline.plan(req, start)
                plans.append(time.perf_counter() - t0)
                if res.planner:
                    ompl.append(plans[-1])
                lim = ctx.limits
                t0 = time.perf_counter()
                plan_path(
                    start, goal, lim.lower, lim.upper, ctx.scene.is_valid, "RRTConnect",
                    try_straight=False,
                )  # fmt: skip
                forced.append(time.perf_counter() - t0)
        tip = ctx.kin.link_pose(goal, "cluedo_link")[0]
        iks = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            q = mg.pipeline.ik(ctx, "cluedo_link", tip, poses["home"])
            iks.append(time.perf_counter() - t0)
            assert q is not None, name
        arm.set_named_target(name)
        ok = arm.go()
        h.rt.run(1.0)
        err = np.abs(np.array(arm.get_current_joint_values()) - goal).max()
        plan_all += plans
        ik_all += iks
        ompl_all += ompl
        forced_all += forced
        print(
            f"{name:<14} {1e3 * np.median(plans):>17.1f} {len(ompl):>4}/{len(plans):<5} "
            f"{_median_ms(ompl):>8} {_median_ms(forced):>7} {1e3 * np.median(iks):>15.2f} "
            f"{err:>15.4f}{'' if ok else '  (FAILED)'}"
        )
    print(
        f"{'all':<14} {1e3 * np.median(plan_all):>17.1f} {len(ompl_all):>4}/{len(plan_all):<5} "
        f"{_median_ms(ompl_all):>8} {_median_ms(forced_all):>7} {1e3 * np.median(ik_all):>15.2f}"
    )


def _median_ms(times: list) -> str:
    return f"{1e3 * np.median(times):.1f}" if times else "-"


if __name__ == "__main__":
    main()
