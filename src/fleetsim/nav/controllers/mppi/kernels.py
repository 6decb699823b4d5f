"""MPPI's batched kernels: noised control sequences, motion models, the softmax update.

All compiled with numba without ``fastmath`` (the same inputs give the same bits, so a seeded
run is reproducible). Arrays are batches of ``B`` sampled control sequences of ``T`` steps;
the last axis of a control or velocity is (vx m/s, vy m/s, wz rad/s), of a pose (x m, y m,
yaw rad) in the costmap's frame.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

DIFF_DRIVE, OMNI, ACKERMANN = 0, 1, 2
MODEL_CODES = {"DiffDrive": DIFF_DRIVE, "Omni": OMNI, "Ackermann": ACKERMANN}


@njit(cache=True, inline="always")
def _clamp(v, lo, hi):
    return lo if v < lo else (hi if v > hi else v)


@njit(cache=True, inline="always")
def _turn(d):
    """(cos d, sin d); Taylor series for the small turns of one model step (libm's cos and
    sin cost ~25x a multiply-add and run 2 x B x T times a cycle), exact to ~1e-10 there."""
    if abs(d) > 0.25:
        return math.cos(d), math.sin(d)
    d2 = d * d
    c = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)))
    s = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))))
    return c, s


@njit(cache=True)
def rollouts(
    sequence,
    noise,
    pose,
    velocity,
    limits,
    model,
    dt,
    min_turning_r,
    controls,
    vels,
    poses,
    headings,
):
    """Sample controls around ``sequence``, propagate velocities and integrate poses.

    Parameters
    ----------
    sequence : (T, 3) the current control sequence.
    noise : (B, T, 3) perturbations (already scaled by each axis' std).
    pose : (3,) the robot's pose (x, y, yaw).
    velocity : (3,) the robot's velocity in its base frame: the first state's.
    limits : (9,) vx_min, vx_max, vy_max, wz_max, ax_min, ax_max, ay_max, az_max (all >= 0 but
        vx_min and ax_min), and 1.0 to apply the acceleration limits (else 0.0).
    model : DIFF_DRIVE, OMNI or ACKERMANN (vy is zero except for OMNI; ACKERMANN bounds |wz| by
        |vx| / min_turning_r).
    dt : model_dt, s.
    controls, vels, poses : (B, T, 3) outputs: the clamped sampled controls (within the
        acceleration limits of the velocity they follow, when applied); the state
        velocities (step 0 the robot's, step t the control of t - 1 within the acceleration
        limits); the poses after each step (pose t integrates velocity t over dt from pose
        t - 1, Euler, the heading of the step's start).
    headings : (B, T, 2) output: cos and sin of each pose's yaw.
    """
    nb, nt = noise.shape[0], noise.shape[1]
    vx_min, vx_max, vy_max, wz_max = limits[0], limits[1], limits[2], limits[3]
    ax_min, ax_max, ay_max, az_max = limits[4], limits[5], limits[6], limits[7]
    acc = limits[8] > 0.5
    c0, s0 = math.cos(pose[2]), math.sin(pose[2])
    for b in range(nb):
        for t in range(nt):
            vx = _clamp(sequence[t, 0] + noise[b, t, 0], vx_min, vx_max)
            vy = 0.0
            if model == OMNI:
                vy = _clamp(sequence[t, 1] + noise[b, t, 1], -vy_max, vy_max)
            wz = _clamp(sequence[t, 2] + noise[b, t, 2], -wz_max, wz_max)
            if model == ACKERMANN and min_turning_r > 0.0:
                bound = abs(vx) / min_turning_r
                wz = _clamp(wz, -bound, bound)
            controls[b, t, 0] = vx
            controls[b, t, 1] = vy
            controls[b, t, 2] = wz
        x, y, yaw, c, s = pose[0], pose[1], pose[2], c0, s0
        px, py, pw = velocity[0], velocity[1] if model == OMNI else 0.0, velocity[2]
        for t in range(nt):
            if t > 0:
                cx, cy, cw = controls[b, t - 1, 0], controls[b, t - 1, 1], controls[b, t - 1, 2]
                if acc:
                    # accelerating away from zero uses ax_max, braking towards it -ax_min
                    if px >= 0.0:
                        cx = _clamp(cx, px + ax_min * dt, px + ax_max * dt)
                    else:
                        cx = _clamp(cx, px - ax_max * dt, px - ax_min * dt)
                    cy = _clamp(cy, py - ay_max * dt, py + ay_max * dt)
                    cw = _clamp(cw, pw - az_max * dt, pw + az_max * dt)
                    # the sample is what the base can follow (as Nav2's models write back)
                    controls[b, t - 1, 0] = cx
                    controls[b, t - 1, 1] = cy
                    controls[b, t - 1, 2] = cw
                px, py, pw = cx, cy, cw
            vels[b, t, 0] = px
            vels[b, t, 1] = py
            vels[b, t, 2] = pw
            x += (px * c - py * s) * dt
            y += (px * s + py * c) * dt
            yaw += pw * dt
            cd, sd = _turn(pw * dt)
            c, s = c * cd - s * sd, s * cd + c * sd
            poses[b, t, 0] = x
            poses[b, t, 1] = y
            poses[b, t, 2] = yaw
            headings[b, t, 0] = c
            headings[b, t, 1] = s


def integrated_poses(velocities: np.ndarray, pose, dt: float) -> np.ndarray:
    """Poses of one velocity sequence: (T, 3) velocities -> (T, 3) poses (as `rollouts`)."""
    v = np.ascontiguousarray(velocities, dtype=np.float64)
    out = np.empty_like(v)
    _integrate_one(v, np.asarray(pose, dtype=np.float64), dt, out)
    return out


@njit(cache=True)
def _integrate_one(v, pose, dt, out):
    x, y, yaw = pose[0], pose[1], pose[2]
    for t in range(v.shape[0]):
        c, s = math.cos(yaw), math.sin(yaw)
        x += (v[t, 0] * c - v[t, 1] * s) * dt
        y += (v[t, 0] * s + v[t, 1] * c) * dt
        yaw += v[t, 2] * dt
        out[t, 0] = x
        out[t, 1] = y
        out[t, 2] = yaw


@njit(cache=True)
def softmax_sequence(costs, controls, sequence, std, gamma, temperature):
    """The control sequence weighted by the samples' softmax (MPPI's update), in place.

    Parameters
    ----------
    costs : (B,) the critics' costs; the control cost ``gamma / std^2 * sum_t u_t * (v_t - u_t)``
        is added to it (an axis with std 0 is skipped).
    controls : (B, T, 3) sampled controls v. sequence : (T, 3) the current sequence u, replaced.
    std : (3,) sampling std per axis. gamma : control cost weight. temperature : > 0 weights by
        ``exp(-(cost - min) / temperature)``; 0 takes the lowest-cost sample.

    Returns
    -------
    (B,) the softmax weights.
    """
    nb, nt = controls.shape[0], controls.shape[1]
    total = costs.copy()
    for a in range(3):
        if std[a] <= 0.0 or gamma == 0.0:
            continue
        k = gamma / (std[a] * std[a])
        for b in range(nb):
            acc = 0.0
            for t in range(nt):
                acc += sequence[t, a] * (controls[b, t, a] - sequence[t, a])
            total[b] += k * acc
    best = 0
    for b in range(1, nb):
        if total[b] < total[best]:
            best = b
    weights = np.zeros(nb)
    if temperature <= 0.0:
        weights[best] = 1.0
    else:
        lo = total[best]
        s = 0.0
        for b in range(nb):
            weights[b] = math.exp(-(total[b] - lo) / temperature)
            s += weights[b]
        for b in range(nb):
            weights[b] /= s
    for t in range(nt):
        for a in range(3):
            acc = 0.0
            for b in range(nb):
                acc += weights[b] * controls[b, t, a]
            sequence[t, a] = acc
    return weights


def shifted_sequence(sequence: np.ndarray, steps: int) -> np.ndarray:
    """The warm start: ``sequence`` moved ``steps`` earlier, the last control repeated."""
    if steps <= 0:
        return sequence.copy()
    steps = min(steps, sequence.shape[0] - 1)
    out = np.empty_like(sequence)
    out[:-steps] = sequence[steps:]
    out[-steps:] = sequence[-1]
    return out
