"""Static obstacles checked with the robot's real footprint, as collvoid's own planner does.

ORCA treats a robot as a disc. Against other robots that is collvoid's model (their shared
radius), but against the local costmap's walls a lizi's circumscribed disc (0.25 m) is much
wider than its body (0.32 m across): two sides of a 0.45 m gap, each nearer than the disc,
leave ORCA no velocity at all, where base_local_planner's footprint-checked rollouts drive
through. collvoid's ROS planner scores its sampled velocities against the costmap with the
footprint (base_local_planner's costmap model) and keeps its velocity obstacles for the robots;
here the same split is made after the fact:

* the static-obstacle half-planes use the footprint's inscribed radius (optimistic, they only
  steer the holonomic velocity through gaps the body fits);
* `first_collisions` rolls each candidate (v, w) command out for ``time_horizon_obst`` with the
  acceleration limits (base_local_planner's generateTrajectory) and lays the footprint outline
  on the costmap at each step (`footprint_cost_at`, LETHAL or NO_INFORMATION: a collision);
* `footprint_safe_command` keeps the planner's command when its rollout is clear, else takes
  the clear one from a (v, w) grid over the robot's limits whose rollout ends nearest where
  the holonomic velocity leads (forwards or backwards: a lizi beside a wall that cannot turn
  on the spot backs out straight), holding the direction of the caller's last replacement
  unless the other way ends `REVERSE_MARGIN` nearer.

The rollout's simulation is base_local_planner's, written again here rather than imported:
`fleetsim.nav.controllers.rollout.trajectory_costs` also scores path and goal distance maps,
which this planner does not have.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from fleetsim.nav.controllers.rollout import new_velocity
from fleetsim.nav.costmap.footprint import footprint_cost_at

#: m: weight of a rad/s of turn-rate difference against a m/s of speed difference when
#: choosing the clear command nearest the wanted one (a point this far from the centre moves
#: as far per rad as the centre per m)
TURN_WEIGHT = 0.3
#: samples of the forward (or backward) speed and of the turn rate in the fallback grid
SPEED_SAMPLES = 11
TURN_SAMPLES = 21
#: fractions of the fastest turn added to the fallback grid on either side of straight: a
#: rectangle beside a wall with its nose a degree in (a jackal's padded footprint 1 cm off the
#: corridor's wall beside a robot parked on its goal) finds every forward command but a crawl
#: hitting the wall (straight on closes the gap, the grid's next turn, 0.16 rad/s, swings the
#: rear corner into it); a turn of a few hundredths of a rad/s peels it off, as a driver does
FINE_TURNS = (1.0 / 64.0, 1.0 / 32.0, 1.0 / 16.0)
_FINE = np.array(FINE_TURNS)  # a constant of the compiled code, not built at every call
#: m: how much nearer where the holonomic velocity leads a fallback command that reverses the
#: direction of the last one (forwards to backwards or back) must end. Scored afresh each cycle
#: from the measured velocity, a rectangle by a wall with its way off to the side took a
#: forward turn one cycle and a backward turn the next and stood for 40 s (a pioneer3at by its
#: goal, the corridor of 4, seed 28; a jackal in the corridor's end, seed 39); holding the
#: direction while it serves as well makes the to-and-fro of a three-point turn
REVERSE_MARGIN = 0.05
#: rollout steps over the horizon (0.05 m apart at 0.5 m/s over 1 s: below a cell's width)
STEPS = 10


@njit(cache=True)
def first_collisions(
    commands, pose, velocity, acc, horizon, steps, costs, origin, resolution, outline, ends
):
    """The first rollout step whose footprint collides, for each command held from ``pose``.

    Parameters
    ----------
    commands : (S, 2) commanded (v m/s, w rad/s) of a differential drive.
    pose : (3,) x, y (m), yaw (rad) in the costmap frame. velocity : (2,) current (v, w).
    acc : (2,) acceleration limits, m/s^2 and rad/s^2 (the command is reached at these rates).
    horizon : s; steps : rollout steps over it.
    costs : (H, W) uint8 costmap; origin : (2,) m; resolution : m.
    outline : (M, 2) footprint outline points, robot frame, m (`outline_points`).
    ends : (S, 2) float64, written with each rollout's last clear position, m.

    Returns
    -------
    (S,) int64: 1..steps, the first colliding step (LETHAL, NO_INFORMATION or off the map
    under the outline); steps + 1 when the whole rollout is clear.
    """
    out = np.empty(commands.shape[0], dtype=np.int64)
    dt = horizon / steps
    for s in range(commands.shape[0]):
        x, y, th = pose[0], pose[1], pose[2]
        v, w = velocity[0], velocity[1]
        out[s] = steps + 1
        ends[s, 0] = x
        ends[s, 1] = y
        for i in range(1, steps + 1):
            v = new_velocity(commands[s, 0], v, acc[0], dt)
            w = new_velocity(commands[s, 1], w, acc[1], dt)
            x += v * math.cos(th) * dt
            y += v * math.sin(th) * dt
            th += w * dt
            if footprint_cost_at(costs, origin[0], origin[1], resolution, outline, x, y, th) < 0:
                out[s] = i
                break
            ends[s, 0] = x
            ends[s, 1] = y
    return out


def collides_at(grid, outline: np.ndarray, pose) -> bool:
    """Whether ``outline`` (M, 2) m at ``pose`` (x, y, yaw) lies on a lethal or unknown cell
    of ``grid`` (costs, origin, resolution)."""
    costs, origin, res = grid
    x, y, yaw = (float(a) for a in pose)
    return footprint_cost_at(costs, float(origin[0]), float(origin[1]), res, outline, x, y, yaw) < 0


def footprint_safe_command(
    wanted: tuple[float, float],
    holonomic: np.ndarray,
    pose: tuple[float, float, float],
    velocity: tuple[float, float],
    grid: tuple[np.ndarray, tuple[float, float], float],
    outline: np.ndarray,
    limits: tuple[float, float, float, float, float, float],
    horizon: float,
    direction: float = 0.0,
) -> tuple[float, float, bool]:
    """``wanted`` (v, w) if its rollout's footprint stays clear of static obstacles, else the
    clear command from a (v, w) grid whose rollout ends nearest where the ``holonomic``
    velocity ((2,) m/s, costmap frame) leads over ``horizon`` (collvoid scores its samples by
    their distance to the holonomic velocity), the nearer to ``wanted`` on a tie.

    grid : (costs (H, W) uint8, origin (2,) m, resolution m); outline : (M, 2) m.
    limits : (fastest backwards (<= 0), fastest forwards (m/s), min turn, max turn (rad/s),
    acc_lim_x, acc_lim_theta): the fallback grid and the rollout's ramps; velocity : the
    measured (v, w).

    direction : the sign of the last fallback command's speed (0: none): a command the other
    way round must end `REVERSE_MARGIN` nearer (standing and turning on the spot are not
    penalised, so where the held direction is blocked standing may win: the caller's wedge).

    When the robot's footprint already collides where it stands, nothing can be judged and
    ``wanted`` is kept; when every command collides, those that collide last compete.
    Returns (v, w, whether ``wanted`` was replaced).
    """
    costs, origin, res = grid
    lo_v, hi_v, lo_w, hi_w, acc_v, acc_w = limits
    origin_a = np.asarray(origin, dtype=np.float64)
    pose_a = np.asarray(pose, dtype=np.float64)
    vel = np.asarray(velocity, dtype=np.float64)
    acc = np.array([acc_v, acc_w])
    if collides_at(grid, outline, pose):
        return wanted[0], wanted[1], False
    ends = np.empty((1, 2))
    first = first_collisions(
        np.array([wanted], dtype=np.float64), pose_a, vel, acc, horizon, STEPS,
        costs, origin_a, res, outline, ends,
    )  # fmt: skip
    if first[0] > STEPS:
        return wanted[0], wanted[1], False
    speeds = np.concatenate(
        [
            np.linspace(min(lo_v, 0.0), 0.0, SPEED_SAMPLES // 2 + 1)[:-1],
            np.linspace(0.0, max(hi_v, 0.0), SPEED_SAMPLES),
        ]
    )
    turns = np.linspace(lo_w, hi_w, TURN_SAMPLES)
    cand = np.stack(np.meshgrid(speeds, turns, indexing="ij"), axis=-1).reshape(-1, 2)
    # the fine turns only under way: on the spot they inch a robot wedged nose first round
    # into the corner, where standing sends it back out (`CollvoidDrive._footprint_clear`)
    moving = speeds[speeds != 0.0]
    fine_turns = np.concatenate((_FINE * lo_w, _FINE * hi_w))
    peel = np.stack(np.meshgrid(moving, fine_turns, indexing="ij"), axis=-1).reshape(-1, 2)
    cand = np.concatenate([cand, peel, [[0.0, 0.0]]])
    ends = np.empty((cand.shape[0], 2))
    steps = first_collisions(
        cand, pose_a, vel, acc, horizon, STEPS, costs, origin_a, res, outline, ends
    )
    target = pose_a[:2] + np.asarray(holonomic, dtype=np.float64) * horizon
    miss = np.hypot(ends[:, 0] - target[0], ends[:, 1] - target[1])
    if direction:
        miss = miss + REVERSE_MARGIN * (cand[:, 0] * direction < 0.0)
    off = np.hypot(cand[:, 0] - wanted[0], TURN_WEIGHT * (cand[:, 1] - wanted[1]))
    best = np.flatnonzero(steps == steps.max())
    k = int(best[np.lexsort((off[best], np.round(miss[best], 3)))[0]])
    return float(cand[k, 0]), float(cand[k, 1]), True
