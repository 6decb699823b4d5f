"""When the collvoid planner hands the plan back to move_base (`NoValidTrajectory`, so that
move_base plans again from where the robot stands): a global plan out of the local costmap's
reach (base_local_planner's ``transformGlobalPlan`` leaves nothing of it), and a plan that runs
through a robot parked in view while the robot makes no progress. The mixed circle of 16
(seeds 3 and 7) had a pioneer3at stand or wander for the rest of the run in each case."""

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from test_collvoid_planner import LIMITS, LIZI, Fleet, SeeingFleet

from fleetsim.nav.controllers.base import NoValidTrajectory
from fleetsim.nav.controllers.collvoid_parked import BLOCKED_TIME, REPLAN_AGAIN
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.costmap.footprint import inside_polygon
from fleetsim.runtime import Node, Runtime


def planner_with_local_costmap(size_m: float):
    """A planner whose local costmap is a ``size_m`` square about the origin."""
    rt = Runtime()
    n = round(size_m / 0.05)
    cm = Costmap2D(n, n, 0.05, -size_m / 2, -size_m / 2)
    node = Node(rt, "move_base", "/robot1")
    costmap_ros = SimpleNamespace(costmap=cm, footprint=LIZI, global_frame="map")
    return CollvoidLocalPlanner.from_namespace(node, costmap_ros, dict(LIMITS), "robot1")


@pytest.mark.parametrize("off", [1.5, 1.9, 2.1, 3.0])
def test_a_plan_beyond_the_local_costmaps_reach_is_handed_back(off):
    """A 4 x 4 m local costmap reaches 2 m: a plan whose nearest point lies farther than that
    raises, with the distance in the message; a nearer one is followed."""
    pl = planner_with_local_costmap(4.0)
    line = np.linspace([off, -1.0], [off, 1.0], 41)
    pl.set_plan(np.c_[line, np.zeros(41)])
    if off > 2.0:
        with pytest.raises(NoValidTrajectory, match=f"{off:.2f} m away.*2.00 m"):
            pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    else:
        cmd = pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        assert cmd.vx >= 0.0


def corridor(goal_of_2):
    """robot1 at (0, 0) bound for (3, 0) along a 0.7 m corridor (too narrow to pass another
    lizi); robot2 standing at ``goal_of_2``, its own goal, where both see each other."""
    walls = [(-1.0, 0.35, 4.0, 1.0), (-1.0, -1.0, 4.0, -0.35)]
    return Corridor([(0.0, 0.0, 0.0), goal_of_2], [(3.0, 0.0, 0.0), goal_of_2], walls=walls)


class Corridor(SeeingFleet):
    """Keeps ``nearest``: the least distance between the two robots' centres (both head along
    the corridor, so their bodies, 0.38 m long, touch below 0.38 m)."""

    nearest = math.inf

    def see(self):
        super().see()
        self.nearest = min(self.nearest, math.dist(self.state[0, :2], self.state[1, :2]))


def test_a_plan_through_a_parked_robot_is_handed_back_once_the_robot_stops_progressing():
    """robot2 stands in the corridor on robot1's plan: robot1 comes up behind it and stops; after
    `BLOCKED_TIME` s without progress its planner raises, naming robot2, and not again for the
    same robot within `REPLAN_AGAIN` s."""
    f = corridor((1.4, 0.0, 0.0))
    t, raised = 0.0, []
    while t < 12.0:
        try:
            f.run(0.1)
        except NoValidTrajectory as err:
            raised.append((t, str(err)))
            f.vel[0] = 0.0
        t += 0.1
    assert raised, "robot1 never handed the blocked plan back"
    first, text = raised[0]
    assert "robot2" in text and "planning again" in text
    assert first >= BLOCKED_TIME
    gaps = np.diff([r[0] for r in raised])
    assert (gaps >= REPLAN_AGAIN - 0.11).all()
    assert f.nearest > 0.38, "robot1's body reached robot2's"


def test_a_robot_parked_on_the_goal_is_not_a_reason_to_plan_again():
    """robot2 stands on robot1's goal: no plan gets past it, so robot1 waits short of it and
    never hands the plan back."""
    f = corridor((3.0, 0.0, 0.0))
    f.run(12.0)
    assert f.nearest > 0.38, "robot1's body reached robot2's"
    assert math.dist(f.state[0, :2], (3.0, 0.0)) > 0.3


def test_inside_polygon_agrees_with_a_dense_grid_for_a_concave_shape():
    """The even-odd rule on an L shape, against its two rectangles."""
    shape = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    xs, ys = np.meshgrid(np.linspace(-0.5, 2.5, 61) + 1e-3, np.linspace(-0.5, 2.5, 61) + 1e-3)
    pts = np.c_[xs.ravel(), ys.ravel()]
    x, y = pts.T
    truth = ((x > 0) & (x < 2) & (y > 0) & (y < 1)) | ((x > 0) & (x < 1) & (y > 0) & (y < 2))
    assert (inside_polygon(pts, shape) == truth).all()
    assert (inside_polygon(pts, shape[::-1]) == truth).all()


@pytest.mark.parametrize("patience", [10.0, 1e3])
def test_a_stuck_robot_passes_between_parked_robots_by_their_bodies(patience):
    """Two lizis parked 0.84 m apart across robot1's way, where no sensor of robot1 sees them:
    their discs close the gap (two 0.25 m discs and robot1's own leave none), their bodies leave
    0.52 m for robot1's 0.32. ORCA keeps robot1 short of them; after ``deadlock_time`` s
    without progress it takes them by their shared footprints and drives through (the mixed
    circle of 16, seed 10: a pioneer3at went to and fro for 80 s before such a gap). With the
    patience out of reach it never arrives."""
    gap = 0.84
    f = Fleet(
        [(0.0, 0.0, 0.0), (1.5, gap / 2, 0.0), (1.5, -gap / 2, 0.0)],
        [(3.0, 0.0, 0.0), (1.5, gap / 2, 0.0), (1.5, -gap / 2, 0.0)],
        deadlock_time=patience,
    )
    reached, nearest = False, math.inf
    for _ in range(150):
        reached = f.run(0.2)
        body = np.abs(f.state[0, 1] - f.state[1:, 1]) - 0.32  # side by side: y gap of bodies
        level = np.abs(f.state[0, 0] - f.state[1:, 0]) < 0.38
        nearest = min(nearest, float(np.where(level, body, np.inf).min()))
        if reached:
            break
    assert reached is (patience < 100.0)
    assert nearest > 0.0, "robot1's body touched a parked one"


def test_move_base_plans_again_from_where_a_robot_pushed_off_its_plan_stands():
    """Through move_base: a lizi with the collvoid planner on its way along y = 1 is carried
    (here: set down) 2.5 m off its plan, beyond its 3 x 3 m local costmap's 1.5 m reach. The
    planner hands the plan back, move_base plans again from where the robot stands, and the
    goal is reached on the new plan."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from nav_world import PLANNER, goal_msg, move_base_params, nav_world

    from fleetsim.msgs.actionlib_msgs import GoalStatus

    params = move_base_params(base_local_planner="collvoid_local_planner/CollvoidLocalPlanner")
    params["CollvoidLocalPlanner"] = {**PLANNER, "max_vel_x": 0.5, "carrot_distance": 0.8}
    w = nav_world(params, start=(1.0, 1.0, 0.0))
    h = w.client.send_goal(goal_msg(3.5, 1.0))
    w.rt.run(duration=20.0, until=lambda: w.bot.pose[0] > 1.8)
    assert len(w.watch.plans) == 1 and not h.done
    w.bot.pose[:] = (2.0, 3.5, 0.0)
    w.rt.run(duration=40.0, until=lambda: h.done)
    assert h.status == GoalStatus.SUCCEEDED
    assert len(w.watch.plans) >= 2
    first = w.watch.plans[-1].poses[0].pose.position
    assert math.dist((first.x, first.y), (2.0, 3.5)) < 0.3
    assert w.bot.min_clearance > 0.0
