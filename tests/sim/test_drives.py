"""The drive servos' support: the held-rotor armature of skid-steer wheels."""

import math

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim.drives import SLIP_RESOLUTION, rotor_armature


def wheel_speed_change(armature: float, radius: float, force: float, timestep: float) -> float:
    """Surface speed change (m/s) of a free wheel (hinge with ``armature``, tiny own inertia)
    pushed at its rim by ``force`` for one MuJoCo step."""
    spec = mujoco.MjSpec()
    spec.option.timestep = timestep
    spec.option.gravity = [0, 0, 0]
    body = spec.worldbody.add_body(name="wheel")
    body.mass, body.inertia, body.explicitinertial = 1e-3, [1e-9] * 3, True
    joint = body.add_joint(name="axle", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 1, 0])
    joint.armature = armature
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qfrc_applied[0] = force * radius
    mujoco.mj_step(model, data)
    return float(data.qvel[0]) * radius


def test_full_friction_moves_the_held_wheel_by_the_slip_resolution():
    mass, radius, n, mu, g, dt = 7.6, 0.077, 4, 1.0, 9.81, 0.004  # lizi
    arm = rotor_armature(mass, radius, n, mu, g, dt)
    assert arm == pytest.approx(0.08841, rel=1e-3)
    dv = wheel_speed_change(arm, radius, mu * mass * g / n, dt)
    assert dv == pytest.approx(SLIP_RESOLUTION, rel=1e-3)


@settings(max_examples=50, deadline=None)
@given(
    mass=st.floats(0.5, 200.0),
    radius=st.floats(0.02, 0.5),
    n=st.integers(1, 8),
    mu=st.floats(0.1, 2.0),
    dt=st.floats(1e-4, 0.01),
    k=st.floats(0.1, 10.0),
)
def test_armature_scales_with_load_radius_squared_and_timestep(mass, radius, n, mu, dt, k):
    base = rotor_armature(mass, radius, n, mu, 9.81, dt)
    assert base > 0
    assert rotor_armature(k * mass, radius, n, mu, 9.81, dt) == pytest.approx(k * base)
    assert rotor_armature(mass, k * radius, n, mu, 9.81, dt) == pytest.approx(k * k * base)
    assert rotor_armature(mass, radius, n, mu, 9.81, k * dt) == pytest.approx(k * base)
    assert rotor_armature(mass, radius, n, mu, -9.81, dt) == pytest.approx(base)
    # full friction on the wheel for one step changes its surface speed by SLIP_RESOLUTION
    impulse = mu * mass * 9.81 / n * dt
    assert impulse * radius**2 / base == pytest.approx(SLIP_RESOLUTION)


def test_no_gravity_or_mass_means_no_armature():
    assert rotor_armature(0.0, 0.1, 4, 1.0, 9.81, 0.004) == 0.0
    assert rotor_armature(10.0, 0.1, 4, 1.0, 0.0, 0.004) == 0.0
    assert np.isfinite(rotor_armature(10.0, 0.1, 0, 1.0, 9.81, 0.004))


def encoder_reference(left, right, radius, sep, t, state):
    """gazebo_ros wheel odometry for one drive, step by step in plain Python (the plugin's
    former per-reading code); ``state`` = [pose, prev_angles, prev_t, twist]."""
    import math

    pose, prev, prev_t, twist = state
    left = sum(float(a) for a in left) / len(left)
    right = sum(float(a) for a in right) / len(right)
    if prev is None:
        return [pose, (left, right), t, twist]
    dl, dr = (left - prev[0]) * radius, (right - prev[1]) * radius
    ds, dth = (dl + dr) / 2, (dr - dl) / sep
    x, y, yaw = pose
    mid = yaw + dth / 2
    pose = (x + ds * math.cos(mid), y + ds * math.sin(mid), yaw + dth)
    if t - prev_t > 0:
        twist = (ds / (t - prev_t), dth / (t - prev_t))
    return [pose, (left, right), t, twist]


@settings(max_examples=40, deadline=None)
@given(
    wheels=st.lists(st.sampled_from([1, 2]), min_size=1, max_size=4),
    seed=st.integers(0, 10_000),
)
def test_encoder_odometry_kernel_equals_the_scalar_rule(wheels, seed):
    from fleetsim.sim.drives import odometry_from_encoders

    rng = np.random.default_rng(seed)
    n = len(wheels)
    counts = [2 * w for w in wheels]  # w left and w right wheels per drive
    start = np.cumsum([0, *counts]).astype(np.int64)
    qpos = np.zeros(start[-1] + 3)
    wheel_q = np.arange(start[-1], dtype=np.int64) + 3
    radius, sep = rng.uniform(0.03, 0.2, n), rng.uniform(0.2, 0.6, n)
    pose, twist = np.zeros((n, 3)), np.zeros((n, 2))
    prev, has_prev, prev_t = np.zeros((n, 2)), np.zeros(n, bool), np.zeros(n)
    states = [[(0.0, 0.0, 0.0), None, None, (0.0, 0.0)] for _ in range(n)]
    t = 0.0
    for _ in range(6):
        t += float(rng.choice([0.0, 0.02, 0.05]))
        qpos[3:] += rng.normal(0, 0.5, len(qpos) - 3)
        slots = np.flatnonzero(rng.random(n) < 0.7).astype(np.int64)
        out = np.empty((len(slots), 13))
        odometry_from_encoders(
            qpos, wheel_q, start, np.array(wheels), radius, sep, slots, t,
            pose, twist, prev, has_prev, prev_t, out,
        )  # fmt: skip
        for k, i in enumerate(slots):
            q = qpos[wheel_q[start[i] : start[i + 1]]]
            states[i] = encoder_reference(
                q[: wheels[i]], q[wheels[i] :], radius[i], sep[i], t, states[i]
            )
            (x, y, yaw), _, _, (v, w) = states[i]
            assert out[k].tolist() == [
                x, y, 0.0, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2), v, 0.0, 0.0, 0.0, 0.0, w
            ]  # fmt: skip
