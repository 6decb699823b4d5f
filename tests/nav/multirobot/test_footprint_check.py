"""Static obstacles against the real footprint (`fleetsim.nav.multirobot.footprint_check`): a
lizi with collvoid drives through a gap its body fits and its circumscribed disc does not
(issue 14's soak: lizis stopped for good between Willow's clutter), the rollout kernel agrees
with the footprint placed pose by pose, and a command into a wall is replaced."""

import itertools
import math

import numpy as np
import pytest
from test_collvoid_planner import BODY, LIZI, Fleet, empty_map

from fleetsim.nav.costmap.footprint import footprint_costs, outline_points, padded_footprint
from fleetsim.nav.multirobot.footprint_check import (
    STEPS,
    first_collisions,
    footprint_safe_command,
)

OUTLINE = outline_points(LIZI, 0.05)
#: the multi-robot scenarios' jackal: its chassis padded by 5 cm, and its limits
JACKAL = np.array([[-0.31, -0.27], [-0.31, 0.27], [0.31, 0.27], [0.31, -0.27]])
JACKAL_LIMITS = {"max_vel_theta": 1.57, "min_vel_theta": -1.57, "min_in_place_vel_theta": 0.5,
                 "acc_lim_x": 2.0, "acc_lim_theta": 3.0}  # fmt: skip


def drive_off_the_walls(f, seconds: float, outline=OUTLINE) -> bool:
    """Run robot 1 of ``f`` for up to ``seconds`` (0.2 s at a time), its footprint (``outline``)
    never on a wall; whether it reached its goal."""
    cm = f.cm
    for _ in range(round(seconds / 0.2)):
        reached = f.run(0.2)
        cost = footprint_costs(
            cm.costs, cm.origin_x, cm.origin_y, cm.resolution, outline, f.state.copy()
        )
        assert cost[0] >= 0.0, f"footprint on a wall at {f.state[0]}"
        if reached:
            return True
    return False


def grid_of(cm):
    return cm.costs, (cm.origin_x, cm.origin_y), cm.resolution


@pytest.mark.parametrize("width", [0.46, 0.5])
def test_a_lizi_drives_through_a_gap_its_body_fits_and_its_disc_does_not(width):
    """Two blocks 0.3 m deep leave a ``width`` gap on the straight plan: narrower than the
    lizi's circumscribed disc (2 x 0.25 m + a cell), wider than its body (0.32 m). The lizi
    starts turned 0.3 rad off the plan; it reaches the goal and its footprint never touches
    a lethal cell on the way."""
    half = width / 2
    walls = [(-0.15, half, 0.15, 2.0), (-0.15, -2.0, 0.15, -half)]
    assert 2 * (BODY + 0.05 * 0.71) > width > 0.32
    f = Fleet([(-2.5, 0.0, 0.3)], [(2.5, 0.0, 0.0)], walls=walls)
    cm = f.cm
    reached = False
    for _ in range(300):
        reached = f.run(0.1)
        cost = footprint_costs(
            cm.costs, cm.origin_x, cm.origin_y, cm.resolution, OUTLINE, f.state.copy()
        )
        assert cost[0] >= 0.0, f"footprint on a wall at {f.state[0]}"
        if reached:
            break
    assert reached, f"stopped at {f.state[0]}, goal (2.5, 0)"
    assert f.state[0, 0] > 2.2


def test_first_collisions_agree_with_the_footprint_pose_by_pose():
    cm = empty_map([(0.5, -1.0, 0.7, 1.0)])
    rng = np.random.default_rng(3)
    cmds = np.c_[rng.uniform(-0.5, 0.5, 40), rng.uniform(-1.0, 1.0, 40)]
    pose = np.array([0.0, 0.1, 0.2])
    vel = np.array([0.2, 0.0])
    acc = np.array([2.5, 3.2])
    ends = np.empty((40, 2))
    got = first_collisions(cmds, pose, vel, acc, 1.0, STEPS, cm.costs,
                           np.array(grid_of(cm)[1]), 0.05, OUTLINE, ends)  # fmt: skip
    dt = 1.0 / STEPS
    for (cv, cw), k, end in zip(cmds, got, ends):
        x, y, th = pose
        v, w = vel
        poses = []
        for _ in range(STEPS):
            v = min(cv, v + 2.5 * dt) if cv >= v else max(cv, v - 2.5 * dt)
            w = min(cw, w + 3.2 * dt) if cw >= w else max(cw, w - 3.2 * dt)
            x, y, th = x + v * math.cos(th) * dt, y + v * math.sin(th) * dt, th + w * dt
            poses.append((x, y, th))
        cost = footprint_costs(cm.costs, -10.0, -10.0, 0.05, OUTLINE, np.array(poses))
        bad = np.flatnonzero(cost < 0)
        assert k == (bad[0] + 1 if bad.size else STEPS + 1)
        last_clear = poses[bad[0] - 1] if bad.size and bad[0] > 0 else poses[-1]
        if bad.size and bad[0] == 0:
            last_clear = pose
        assert end == pytest.approx(np.asarray(last_clear)[:2])
    assert (got <= STEPS).any() and (got > STEPS).any()


def test_a_command_into_a_wall_is_replaced_by_the_nearest_clear_one():
    cm = empty_map([(0.45, -1.0, 0.65, 1.0)])  # 0.26 m ahead of the lizi's nose
    limits = (-0.5, 0.5, -1.0, 1.0, 2.5, 3.2)
    pose, vel = (0.0, 0.0, 0.0), (0.0, 0.0)
    ahead = np.array([0.5, 0.0])
    v, w, replaced = footprint_safe_command((0.5, 0.0), ahead, pose, vel, grid_of(cm), OUTLINE,
                                            limits, 1.0)  # fmt: skip
    assert replaced and 0.0 <= v < 0.5 and w == pytest.approx(0.0)
    # its own rollout is clear
    k = first_collisions(np.array([[v, w]]), np.array(pose), np.array(vel), np.array([2.5, 3.2]),
                         1.0, STEPS, cm.costs, np.array(grid_of(cm)[1]), 0.05, OUTLINE,
                         np.empty((1, 2)))  # fmt: skip
    assert k[0] == STEPS + 1
    # away from the wall nothing is replaced
    assert footprint_safe_command((0.5, 0.2), ahead, (-2.0, 0.0, 0.0), vel, grid_of(cm),
                                  OUTLINE, limits, 1.0) == (0.5, 0.2, False)  # fmt: skip


def test_a_rectangle_a_degree_nose_in_beside_a_wall_peels_off_it():
    """The jackals' corridor of 4 (seed 0): jackal1 (0.62 x 0.54 m with its padding) 1 cm
    below the wall beside a robot parked on its goal, its nose 1 degree in, its holonomic
    velocity ahead and away from the wall. Every forward command of the fallback grid at 0.3
    m/s or more hits the wall (straight on closes the 1 cm, the grid's next turn swings the
    rear corner into it), so the nearest clear one was a crawl, and the crawl and the escape
    behind it went to and fro for 40 s. A turn of a few hundredths of a rad/s keeps the body
    off the wall and the speed up."""
    from fleetsim.nav.multirobot.footprint_check import TURN_SAMPLES

    jackal = [[-0.31, -0.27], [-0.31, 0.27], [0.31, 0.27], [0.31, -0.27]]
    outline = outline_points(jackal, 0.05)
    cm = empty_map([(-3.0, 0.25, 3.0, 0.6)])
    pose, vel = (0.0, -0.03, math.radians(1.0)), (0.1, 0.0)
    limits = (-0.5, 0.5, -1.57, 1.57, 2.0, 3.0)
    acc = np.array([2.0, 3.0])
    origin = np.array(grid_of(cm)[1])
    coarse = np.array([[v, w] for v in np.linspace(0.3, 0.5, 5)
                       for w in np.linspace(-1.57, 1.57, TURN_SAMPLES)])  # fmt: skip
    hit = first_collisions(coarse, np.array(pose), np.array(vel), acc, 1.0, STEPS, cm.costs,
                           origin, 0.05, outline, np.empty((len(coarse), 2)))  # fmt: skip
    assert (hit <= STEPS).all()  # the premise: no coarse command at speed is clear
    v, w, replaced = footprint_safe_command((0.5, -0.3), np.array([0.45, -0.15]), pose, vel,
                                            grid_of(cm), outline, limits, 1.0)  # fmt: skip
    assert replaced and v >= 0.3 and -0.2 < w < 0.0
    k = first_collisions(np.array([[v, w]]), np.array(pose), np.array(vel), acc, 1.0, STEPS,
                         cm.costs, origin, 0.05, outline, np.empty((1, 2)))  # fmt: skip
    assert k[0] == STEPS + 1


@pytest.mark.parametrize("escape", [True, False])
def test_a_lizi_wedged_nose_first_backs_out_and_goes_through(escape, monkeypatch):
    """Issue 14's lizi7 at (24.84, 44.70): a block 3.5 cm ahead of the lizi's right front
    corner, a wall 0.2 m above its left side, the plan through the 0.4 m gap between them.
    No arc is clear and a turn on the spot hits the block, so the clear command nearest the
    holonomic velocity is to stand: it stood until move_base gave up. Backing out straight
    0.15 m (base_local_planner's escape) leaves room for an arc into the gap."""
    if not escape:
        monkeypatch.setattr("fleetsim.nav.controllers.collvoid_drive.ESCAPE_SPEED", 0.0)
    walls = [(0.225, -1.0, 0.5, -0.025), (0.15, 0.375, 0.6, 1.5), (-0.05, 0.3, 0.05, 1.5)]
    f = Fleet([(0.0, 0.0, 0.0)], [(3.0, 0.17, 0.0)], walls=walls)
    corners = np.array([[0, 0, 0], [0.3, 0.12, 0], [0.6, 0.17, 0], [3, 0.17, 0]], float)
    f.planners[0].set_plan(
        np.concatenate([np.linspace(a, b, 20) for a, b in itertools.pairwise(corners)])
    )
    assert drive_off_the_walls(f, 30.0) is escape
    assert (f.planners[0].escapes >= 1) is escape


@pytest.mark.parametrize("turn", [True, False])
def test_a_jackal_wedged_nose_in_towards_a_parked_robot_backs_out_turning_away(turn, monkeypatch):
    """The jackals' corridor of 4, seed 3: jackal1 (0.62 x 0.54 m with its padding) between
    the corridor's wall and jackal3 parked on its goal, its nose 13 degrees in towards jackal3,
    its way on along the wall. Every right turn swings its front corner into jackal3, and from
    where a straight escape leaves it a crawl turning left is the clear move nearest the
    holonomic velocity: it inched in and backed out for the rest of the run. Backing out on a
    curve that turns it towards the holonomic velocity leaves it facing along the wall."""
    if not turn:
        monkeypatch.setattr("fleetsim.nav.controllers.collvoid_drive.ESCAPE_TURN", 0.0)
    walls = [(-3.0, -1.5, 3.0, -0.45), (0.30, 0.30, 0.92, 0.84)]  # the wall, jackal3's body
    f = Fleet([(0.0, 0.0, math.radians(13.0))], [(2.5, -0.1, 0.0)], walls=walls,
              footprint=JACKAL, **JACKAL_LIMITS)  # fmt: skip
    assert drive_off_the_walls(f, 20.0, outline_points(JACKAL, 0.05)) is turn
    assert f.planners[0].escapes >= 1
    if not turn:
        assert f.planners[0].escapes > 5  # to and fro


@pytest.mark.parametrize("padding", [0.05, 0.0])
def test_a_jackal_flush_on_a_wall_peels_off_within_its_padding(padding):
    """The jackals' corridor of 4, seed 27: jackal1 passed jackal3 parked on its goal along
    the wall and ended with its padded footprint flush on the wall's cells, its goal 0.8 m
    ahead and 0.65 m off the wall, the corridor's end wall beyond. A rectangle flush on a wall
    cannot turn either way (each turn swings a wall-side corner into it), and straight on
    ends at the end wall: it crept ahead and escaped back for the rest of the run. Wedged
    again where it was wedged before, it turns off the wall within its padding (0.05 m), its
    body never on a lethal cell. Without a padding to use (``padding`` 0: the same footprint
    as the body) it stays wedged."""
    body = padded_footprint(JACKAL, -0.05)  # the chassis, 0.52 x 0.44 m
    walls = [(-3.0, 0.30, 3.0, 1.5), (1.55, -1.5, 3.0, 1.5), (-3.0, -1.5, 3.0, -1.2)]
    f = Fleet([(0.0, 0.029, 0.0)], [(0.8, -0.62, 0.0)], walls=walls, footprint=JACKAL,
              padding=padding, **JACKAL_LIMITS)  # fmt: skip
    f.planners[0].set_plan(np.array([[x, 0.0 if x < 0.6 else -0.62 * (x - 0.6) / 0.2, 0.0]
                                     for x in np.linspace(0.0, 0.8, 17)]))  # fmt: skip
    assert drive_off_the_walls(f, 20.0, outline_points(body, 0.05)) is (padding > 0.0)
    assert (f.planners[0].way_outs >= 1) is (padding > 0.0)


def test_a_fallback_command_holds_its_direction_while_it_serves():
    """The holonomic velocity points square to the lizi's left and a wall ahead refuses the
    wanted command: a forward turn left and a backward turn right end about as near where it
    leads. Scored afresh from the measured velocity each cycle, a pioneer3at by its goal took
    one, then the other, and stood for 40 s (the corridor of 4, seed 28). The way the last
    fallback command went is held unless the other way ends `REVERSE_MARGIN` nearer; where
    that way is blocked it is not taken (the robot stands, and its drive escapes)."""
    limits = (-0.5, 0.5, -1.5, 1.5, 2.0, 3.0)

    def args(wall):  # at the origin facing +x, standing; wanted: straight on; holo: left
        grid = grid_of(empty_map([wall]))
        return (0.5, 0.0), np.array([0.0, 0.3]), (0.0, 0.0, 0.0), (0.0, 0.0), grid, OUTLINE

    ahead = args((0.6, -1.0, 0.8, 1.0))
    v0, w0, replaced = footprint_safe_command(*ahead, limits, 1.0)
    assert replaced and v0 > 0.0 and w0 > 0.0  # ahead, turning left (nearest the wanted one)
    assert footprint_safe_command(*ahead, limits, 1.0, 1.0)[:2] == (v0, w0)
    vb, wb, _ = footprint_safe_command(*ahead, limits, 1.0, -1.0)
    assert vb < 0.0 and wb < 0.0  # backing, turning right: its centre goes left all the same
    # a wall 1 cm from its nose: the direction held is blocked, so it is not taken (it
    # stands, where the backward turn is not REVERSE_MARGIN nearer; then it is wedged)
    nose = args((0.21, -1.0, 0.4, 1.0))
    assert footprint_safe_command(*nose, limits, 1.0)[0] < 0.0
    assert footprint_safe_command(*nose, limits, 1.0, 1.0)[:2] == (0.0, 0.0)


def test_the_drive_hands_the_last_fallbacks_direction_to_the_next_and_drops_it_on_a_new_goal(
    monkeypatch,
):
    """The direction held (`REVERSE_MARGIN`) is that of the last cycle's replacement: none
    after a cycle whose command stood, none for a new goal or after the goal turn."""
    seen, answers = [], iter([(0.2, 0.1, True), (-0.1, 0.0, True), (0.3, 0.0, False)] * 9)

    def fake(wanted, holonomic, pose, velocity, grid, outline, limits, horizon, direction=0.0):
        seen.append(direction)
        return next(answers)

    monkeypatch.setattr("fleetsim.nav.controllers.collvoid_drive.footprint_safe_command", fake)
    f = Fleet([(0.0, 0.0, 0.0)], [(3.0, 0.0, 0.0)])
    pl = f.planners[0]
    for _ in range(4):
        pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert seen == [0.0, 1.0, -1.0, 0.0]  # ahead, back, kept (not replaced), ahead
    pl.set_plan(np.array([[0.0, 0.0, 0.0], [0.0, 2.0, 0.0]]))  # a new goal 3.6 m away
    pl.compute_velocity_commands((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert seen[-1] == 0.0 and pl.fallback_v == -0.1
    pl.compute_velocity_commands((0.0, 2.0, 0.0), (0.0, 0.0, 0.0))  # within the goal: turning
    assert pl.fallback_v == 0.0


def test_the_escape_turns_towards_the_holonomic_velocity_then_tries_straight():
    from types import SimpleNamespace

    from fleetsim.nav.controllers.collvoid_drive import (
        ESCAPE_DISTANCE,
        ESCAPE_TURN,
        CollvoidDrive,
    )

    def turns(holo, yaw, lo=-1.5, hi=1.5):
        stub = SimpleNamespace(
            last_holo=np.array(holo), params=SimpleNamespace(max_vel_theta=hi, min_vel_theta=lo)
        )
        return CollvoidDrive._escape_turns(stub, yaw, 0.1)

    # facing 0.3 rad left of the velocity: turn right, to face it after ESCAPE_DISTANCE
    right = turns([0.3, 0.0], 0.3)
    assert right[0] == pytest.approx(-0.3 * 0.1 / ESCAPE_DISTANCE) and right[1] == 0.0
    assert turns([0.3, 0.0], -0.3)[0] == pytest.approx(0.3 * 0.1 / ESCAPE_DISTANCE)
    # across the +-pi seam the short way round; capped at ESCAPE_TURN of the fastest turn
    assert turns([-0.3, -0.01], math.pi - 0.1)[0] > 0.0
    assert turns([0.0, -0.3], math.pi / 2)[0] == pytest.approx(-ESCAPE_TURN * 1.5)
    assert turns([0.3, 0.0], 0.0) == [0.0]  # already facing it: straight only
    # a base that cannot turn clockwise (min_vel_theta >= 0) never turns that way
    assert turns([0.3, 0.0], 0.3, lo=0.2) == [0.0]


def test_a_wedged_lizi_does_not_back_out_into_a_robot_standing_behind_it():
    """As above, with another lizi standing 3 cm behind its body's disc (the mixed circle of
    16, seed 6: a pioneer3at wedged nose first backed into a lizi). The costmap check has the
    other robots' images cleared, so the escape now also needs the robots' half-planes: it
    does not back out, and the two never come closer."""
    walls = [(0.225, -1.0, 0.5, -0.025), (0.15, 0.375, 0.6, 1.5), (-0.05, 0.3, 0.05, 1.5)]
    behind = (-(2 * BODY + 0.03), 0.0, 0.0)
    f = Fleet([(0.0, 0.0, 0.0), behind], [(3.0, 0.17, 0.0), behind], walls=walls)
    corners = np.array([[0, 0, 0], [0.3, 0.12, 0], [0.6, 0.17, 0], [3, 0.17, 0]], float)
    f.planners[0].set_plan(
        np.concatenate([np.linspace(a, b, 20) for a, b in itertools.pairwise(corners)])
    )
    start = float(np.hypot(*(f.state[0, :2] - f.state[1, :2])))
    for _ in range(25):
        f.run(0.2)
        gap = float(np.hypot(*(f.state[0, :2] - f.state[1, :2])))
        assert gap >= start - 1e-3, f"backed towards the lizi behind: {gap:.3f} m"
    assert f.planners[0].escapes == 0


@pytest.mark.parametrize("escape", [True, False])
def test_a_lizi_wedged_tail_first_escapes_ahead(escape, monkeypatch):
    """The mixed circle of 16, seed 3: pioneer16 stood 0.4 m from its goal for the rest of the
    run, the goal behind its right side, a parked robot at its left rear corner (every turn
    towards the goal swept that corner into it) and no room to back out. Here a wall 3 cm
    behind the lizi and a block at its left rear corner, the goal behind it on the right:
    straight ahead is clear, and escaping that way (base_local_planner's escape, the other way
    round) leaves room to turn. Without the escape it stands for good."""
    if not escape:
        monkeypatch.setattr("fleetsim.nav.controllers.collvoid_drive.ESCAPE_SPEED", 0.0)
    walls = [(-0.30, 0.21, -0.05, 0.6), (-0.40, -0.6, -0.22, 0.6)]
    f = Fleet([(0.0, 0.0, 0.0)], [(-1.0, -1.0, -1.57)], walls=walls)
    assert drive_off_the_walls(f, 15.0) is escape
    assert (f.planners[0].escapes >= 1) is escape
    assert f.backed[0] == 0.0


def test_walls_that_turn_the_disc_back_from_a_gap_the_body_fits_leave_it_no_way_on():
    """A lizi at the mouth of a 0.44 m gap, two corners 0.27 m from its centre ahead on either
    side: inside its circumscribed disc (0.25 m + a cell), outside its inscribed one. The disc's
    program pushes it straight back out of the gap, fast (more than WALLS_BLOCK of the preferred
    speed): that is no way on either, so the inscribed disc steers it in (a jackal flipped
    between the two discs at such a mouth beside a parked robot for 90 s)."""
    walls = [(0.15, 0.22, 0.6, 1.5), (0.15, -1.5, 0.6, -0.22)]
    f = Fleet([(0.0, 0.0, 0.0)], [(2.5, 0.0, 0.0)], walls=walls)
    pl = f.planners[0]
    xy = np.zeros(2)
    holo = pl.holonomic_velocity(xy, 0.0, np.zeros(2), np.array([1.2, 0.0]), 2.5)
    assert pl.walls_blocked
    assert holo[0] > 0.05, holo
