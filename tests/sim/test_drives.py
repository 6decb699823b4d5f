"""The drive servos' support: the held-rotor armature of skid-steer wheels."""

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
