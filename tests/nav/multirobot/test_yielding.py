"""Where a yielding robot goes: passage widths from the costmap, the refuge back along its plan
(the wide place, aside to the right), the other robot gone by; and the whole manoeuvre in the
kinematic fleet: a swap through a passage too narrow for two."""

import math

import numpy as np
import pytest
from test_collvoid_planner import Fleet

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D
from fleetsim.nav.multirobot.yielding import (
    Retreat,
    clear_distance,
    has_passed,
    narrow_between,
    passage_width,
    refuge,
    retreat_velocity,
)

RES = 0.05


def narrow_corridor_walls(width=1.0, bay=2.0, half=6.0, bay_length=3.0):
    """Walls (x0, y0, x1, y1) of a closed corridor 2 * half long, ``bay`` wide for
    ``bay_length`` at each end and ``width`` wide between (centred on y = 0)."""
    w, b, x0 = width / 2, bay / 2, half - bay_length
    return [
        (-half - 0.2, b, half + 0.2, b + 0.2),
        (-half - 0.2, -b - 0.2, half + 0.2, -b),
        (-half - 0.2, -b - 0.2, -half, b + 0.2),
        (half, -b - 0.2, half + 0.2, b + 0.2),
        (-x0, w, x0, b),
        (-x0, -b, x0, -w),
    ]


def costmap(walls, size=(400, 400), origin=(-10.0, -10.0)):
    cm = Costmap2D(size[0], size[1], RES, *origin)
    for x0, y0, x1, y1 in walls:
        c0, c1 = round((x0 - origin[0]) / RES), round((x1 - origin[0]) / RES)
        r0, r1 = round((y0 - origin[1]) / RES), round((y1 - origin[1]) / RES)
        cm.costs[max(r0, 0) : max(r1, 0), max(c0, 0) : max(c1, 0)] = LETHAL_OBSTACLE
    return cm


def args(cm):
    return cm.costs, (cm.origin_x, cm.origin_y), cm.resolution


def test_passage_width_across_the_narrow_part_and_the_bay():
    cm = costmap(narrow_corridor_walls())
    east = np.array([1.0, 0.0])
    left, right = passage_width(*args(cm), np.array([0.0, 0.0]), east, 3.0)
    assert left + right == pytest.approx(1.0, abs=2 * RES)
    assert left == pytest.approx(right, abs=RES)
    left, right = passage_width(*args(cm), np.array([4.5, 0.5]), east, 3.0)
    assert (left, right) == (pytest.approx(0.5, abs=RES), pytest.approx(1.5, abs=RES))
    # capped at the reach; past the costmap's edge counts as clear
    assert clear_distance(*args(cm), np.array([0.0, 0.0]), east, 2.0) == 2.0
    small = costmap([], size=(20, 20), origin=(0.0, 0.0))
    assert clear_distance(*args(small), np.array([0.5, 0.5]), east, 3.0) == 3.0


def test_refuge_is_the_first_wide_place_back_along_the_plan_aside_to_the_right():
    cm = costmap(narrow_corridor_walls())
    plan = np.c_[np.linspace(5.0, -5.0, 201), np.zeros(201)]  # robot2's way west
    here = int(np.argmin(np.abs(plan[:, 0] - 0.5)))
    point, wide = refuge(plan[:, :2], here, *args(cm), 0.31, 0.25)
    assert wide
    assert point[0] == pytest.approx(3.0, abs=0.1)  # the bay begins at x = 3
    # aside to its right (north, facing west), its body clear of the bay's wall
    assert 0.3 < point[1] <= 1.0 - 0.31
    # already in a wide place: it waits where it is, aside
    point, wide = refuge(plan[:, :2], 20, *args(cm), 0.31, 0.25)
    assert wide and point[0] == pytest.approx(plan[20, 0])


def test_refuge_set_back_stays_in_the_wide_place_and_waits_for_the_window():
    cm = costmap(narrow_corridor_walls())
    plan = np.c_[np.linspace(5.0, -5.0, 201), np.zeros(201)]
    here = int(np.argmin(np.abs(plan[:, 0] - 0.5)))
    point, wide = refuge(plan[:, :2], here, *args(cm), 0.31, 0.25, setback=0.8)
    assert wide and point[0] == pytest.approx(3.8, abs=0.1) and point[1] > 0.3
    # the bay ends 2 m on (x = 5): the setback stops where the plan stops being wide
    point, wide = refuge(plan[:, :2], here, *args(cm), 0.31, 0.25, setback=5.0)
    assert wide and 4.0 < point[0] < 5.0
    # a window ending 0.3 m into the bay: the refuge is not final until the setback is seen
    window = costmap(narrow_corridor_walls(), size=(66, 80), origin=(0.0, -2.0))
    point, wide = refuge(plan[:, :2], here, *args(window), 0.31, 0.25, setback=0.8)
    assert not wide and point[0] <= 3.3 + 1e-9


def test_narrow_between_two_robots_facing_each_other():
    cm = costmap(narrow_corridor_walls())
    # both in the bays, the narrow part between them
    assert narrow_between(*args(cm), np.array([-4.0, 0.0]), np.array([4.0, 0.0]), 0.31, 0.25)
    # both in one bay, or in the open
    assert not narrow_between(*args(cm), np.array([3.5, 0.0]), np.array([5.5, 0.0]), 0.31, 0.25)
    assert not narrow_between(
        *args(costmap([])), np.array([-4.0, 0.0]), np.array([4.0, 0.0]), 0.31, 0.25
    )


def test_refuge_beyond_the_rolling_window_is_the_farthest_plan_point_inside_it():
    # a 4 x 4 m window at (-2..2, -2..2) over the narrow part: no wide place in view
    cm = costmap(narrow_corridor_walls(), size=(80, 80), origin=(-2.0, -2.0))
    plan = np.c_[np.linspace(5.0, -5.0, 201), np.zeros(201)]
    here = int(np.argmin(np.abs(plan[:, 0] - 0.0)))
    point, wide = refuge(plan[:, :2], here, *args(cm), 0.31, 0.25)
    assert not wide
    assert point == pytest.approx([1.95, 0.0], abs=0.06)


def test_the_other_robot_has_passed_once_it_is_clear_behind():
    west = np.array([-1.0, 0.0])  # our way to the goal
    assert not has_passed(np.array([-2.0, 0.5]), west, 0.6)  # still ahead
    assert not has_passed(np.array([0.3, 0.6]), west, 0.6)  # beside us
    assert has_passed(np.array([0.7, 0.6]), west, 0.6)
    v = retreat_velocity(np.zeros(2), np.array([3.0, 0.0]), 0.5, 0.6)
    assert v == pytest.approx([0.5, 0.0])
    assert np.all(retreat_velocity(np.zeros(2), np.array([0.01, 0.0]), 0.5, 0.6) == 0.0)


def test_swap_through_a_passage_too_narrow_for_two():
    """1.0 m between the walls for 6 m, 2 m wide bays at the ends: the lizis meet nose to nose;
    robot2 (lower priority) sees the passage is too narrow, yields after narrow_deadlock_time
    (not deadlock_time), backs out into its bay, waits aside, then both finish. Without the rule
    they never do."""
    walls = narrow_corridor_walls()
    swap = ([(-5, 0, 0), (5, 0, math.pi)], [(5, 0, 0), (-5, 0, math.pi)])
    stuck = Fleet(*swap, walls=walls, deadlock_time=1000.0, narrow_deadlock_time=1000.0)
    assert not stuck.run(30.0)
    f = Fleet(*swap, walls=walls, deadlock_time=1000.0)
    assert f.run(60.0)
    assert f.min_gap > 0.0
    assert f.planners[1].deadlock.yields == 1 and f.planners[0].deadlock.yields == 0
    assert np.all(np.abs(f.state[:, 1]) < 1.0 - 0.25)
    # robot2 backs out (no half-turns on the spot), robot1 never drives backwards
    assert f.backed[1] > 2.0 and f.backed[0] == 0.0
    turned = Fleet(*swap, walls=walls, deadlock_time=1000.0, max_vel_x_backwards=0.0)
    assert turned.run(60.0) and turned.backed[1] == 0.0 and turned.min_gap > 0.0


def test_a_wall_marked_as_a_dotted_line_still_bounds_the_passage():
    """A laser marks a wall it sees at a grazing angle every few cells; a probe must not pass
    between the dots."""
    cm = costmap(narrow_corridor_walls())
    holes = np.zeros_like(cm.costs, dtype=bool)
    holes[:, ::3] = holes[:, 1::3] = True  # two cells of every three cleared
    cm.costs[holes] = 0
    for x in np.arange(-2.0, 2.0, 0.05):  # wherever the probe crosses
        left, right = passage_width(*args(cm), np.array([x, 0.0]), np.array([1.0, 0.0]), 3.0)
        assert left + right < 1.2


def test_retreat_keeps_the_way_it_came_and_cuts_the_retreat_off_after_a_yield():
    cm = costmap(narrow_corridor_walls())
    r = Retreat()
    for x in np.arange(-5.0, 0.01, 0.02):  # robot1 drives east to the middle
        r.extend(np.array([x, 0.0]))
    steps = np.hypot(*np.diff(np.array(r.trail), axis=0).T)
    assert np.all((steps >= 0.1) & (steps < 0.13)) and r.trail[0] == (-5.0, 0.0)
    v = r.velocity(args(cm), np.array([0.0, 0.0]), 0.31, 0.25, 0.5, 0.6)
    assert v[0] < 0  # back west, into the narrow part's wide end
    # REFUGE_SETBACK (0.6 m) past the bay's mouth at x = -3, aside (south: robot1 faces east)
    assert r.refuge_final and -3.9 < r.refuge[0] < -3.5 and r.refuge[1] < -0.3
    r.extend(np.array([-2.0, 0.0]))  # the yield is over where the robot now stands
    assert r.refuge is None and r.trail[-1] == pytest.approx((-2.0, 0.0), abs=0.06)
    r.reset()  # a new goal: the way it came is still free
    assert r.refuge is None and r.trail[-1] == pytest.approx((-2.0, 0.0), abs=0.06)


def test_with_no_wide_place_on_the_whole_trail_the_refuge_is_its_far_end():
    """A closed corridor 1.0 m wide, all of it in view: nowhere wide enough for two, so the
    yielder backs out to where its trail began (the way it came, as far as it goes)."""
    cm = costmap([(-6.2, 0.5, 6.2, 0.7), (-6.2, -0.7, 6.2, -0.5)])
    trail = np.c_[np.arange(-4.0, 2.01, 0.1), np.zeros(61)]
    point, wide = refuge(trail, trail.shape[0] - 1, *args(cm), 0.31, 0.25)
    assert not wide and point == pytest.approx([-4.0, 0.0])


def test_a_yielder_replanned_every_cycle_still_backs_out_along_the_way_it_came():
    """move_base hands the plan over every cycle in the odom frame; under amcl the goal there
    moves by a few cm with each map -> odom correction, which the planner takes for a new goal
    (Retreat.reset). The trail must survive it: a yielder whose trail was cleared had nowhere
    to go and waited in the middle of the passage (swap_corridor localization:=amcl)."""
    cm = costmap(narrow_corridor_walls())
    r = Retreat()
    for x in np.arange(-5.0, 0.01, 0.02):
        r.reset()  # a replan under amcl
        r.extend(np.array([x, 0.0]))
    r.reset()
    v = r.velocity(args(cm), np.array([0.0, 0.0]), 0.31, 0.25, 0.5, 0.6)
    assert v[0] < -0.4 and r.refuge_final and r.refuge[0] < -3.4


def test_a_replan_during_the_yield_still_cuts_the_trail_where_the_robot_backed_to():
    """A reset (a replan under amcl) while backing out must not make the trail grow on from
    the farthest point reached: the way back from there would lead forwards, into the other
    robot."""
    cm = costmap(narrow_corridor_walls())
    r = Retreat()
    for x in np.arange(-5.0, 0.01, 0.02):
        r.extend(np.array([x, 0.0]))
    r.velocity(args(cm), np.array([0.0, 0.0]), 0.31, 0.25, 0.5, 0.6)  # backing out
    r.reset()
    r.extend(np.array([-1.5, 0.0]))  # a cycle not yielding, 1.5 m back
    assert r.trail[-1] == pytest.approx((-1.5, 0.0), abs=0.06)
    assert max(p[0] for p in r.trail) < -1.4


def test_a_trail_pushed_sideways_is_not_a_wide_place():
    """Pushed aside by a few cm while yielding, the trail steps across the corridor; the
    passage is measured across the way it runs, not along the corridor."""
    cm = costmap([(-6.2, 1.0, 6.2, 1.2), (-6.2, -1.2, 6.2, -1.0)])  # 2 m wide
    xs = np.arange(-4.0, 0.01, 0.1)
    trail = np.c_[xs, np.zeros_like(xs)]
    trail = np.r_[trail, [[0.0, 0.1], [0.0, 0.2]]]  # the last two steps sideways
    point, wide = refuge(trail, trail.shape[0] - 1, *args(cm), 0.85, 0.95)
    assert not wide and abs(point[1]) < 1.0
