"""Physics health: MuJoCo's warnings as fleetsim errors and log records, never silent.

MuJoCo counts trouble in ``data.warning``: NaN, infinite or huge (> 1e10) positions, velocities,
accelerations or controls, a singular inertia, contact or constraint memory exhausted. By
default it then resets the whole world to its initial state and writes ``MUJOCO_LOG.TXT``, and a
run carries on with robots teleported home. fleetsim instead

- disables the auto-reset (``build.new_world_spec`` sets ``mjDSBL_AUTORESET``),
- routes MuJoCo's warning text to the ``fleetsim.mujoco`` logger (`route_mujoco_warnings`), so
  no ``MUJOCO_LOG.TXT`` is written,
- has the engine look at the counters after every physics step (`WarningWatch`, a fraction of a
  microsecond against ~150 us for a 10-robot step) and raise `physics_error` when one trips,
- redoes with CG the rare steps on which the Newton solver stalled (`SolverGuard`): an
  unconverged contact solve is how robots pushing wheel against wheel got flung into NaN.

Every counter is an error. An unstable state (`PhysicsInstability`) names the robot, body and
joint of the bad degree of freedom, the sim time, the likely cause and what to try. Running out
of contact or constraint memory (`PhysicsBufferFull`) is an error too, not a warning: MuJoCo then
drops contacts, robots pass through walls and each other, and every later result is wrong.
"""

from __future__ import annotations

import logging

import mujoco
import numba
import numpy as np

from fleetsim.errors import PhysicsBufferFull, PhysicsInstability, SimulationError

_log = logging.getLogger("fleetsim.mujoco")
W = mujoco.mjtWarning
#: a link lighter than this share of its robot's mass is "near-massless"
LIGHT_LINK_SHARE = 1e-3
#: an actuator force over the DOF's inertia above this (rad/s^2 or m/s^2) is "huge"
HUGE_ACCELERATION = 1e4
#: contact overlap (m) that counts as a penetration deep enough to blow up the solver
DEEP_PENETRATION = 0.01
#: motion per physics step (rad or m) beyond which a body moves too fast to integrate
RUNAWAY_STEP = 0.5
_FREE_AXES = ("x", "y", "z", "rotation about x", "rotation about y", "rotation about z")
_QUANTITY = {
    W.mjWARN_BADQACC: "acceleration (qacc)",
    W.mjWARN_BADQVEL: "velocity (qvel)",
    W.mjWARN_BADQPOS: "position (qpos)",
}


#: the first words of MuJoCo's text for each counted warning (``mju_warningText``)
_COUNTED = tuple(mujoco.mju_warningText(w, 0)[:20] for w in range(int(W.mjNWARNING)))


def _log_mujoco_warning(text: str) -> None:
    # a counted warning becomes the engine's error, which says more (robot, body, cause): its
    # bare text only at debug level, so a run that stops prints one line, not two
    level = logging.DEBUG if text.startswith(_COUNTED) else logging.WARNING
    _log.log(level, "MuJoCo: %s", text)


def route_mujoco_warnings() -> None:
    """Send MuJoCo's warning text to the ``fleetsim.mujoco`` logger instead of
    ``MUJOCO_LOG.TXT`` and stdout (process-wide; idempotent)."""
    if mujoco.get_mju_user_warning() is not _log_mujoco_warning:
        mujoco.set_mju_user_warning(_log_mujoco_warning)


class WarningWatch:
    """The warning counters of one ``MjData``, checked for any non-zero value."""

    def __init__(self, data: mujoco.MjData) -> None:
        self.number = data.warning.number  # a view into mjData: always current
        self._clear = bytes(self.number.nbytes)

    def tripped(self) -> bool:
        # comparing raw bytes costs ~0.2 us, ndarray.any() ~1 us; this runs after every step
        return self.number.tobytes() != self._clear


class SolverGuard:
    """Steps on which MuJoCo's Newton solver stalled, redone with the CG solver.

    Newton with elliptic friction cones can stall on the contacts between two robots' spinning
    drive wheels (each with its held rotor, ``drives.rotor_armature``): in the willow10_amcl
    repro it ran to its iteration cap with a gradient of 69, and the unconverged contact forces
    put 200 N m of roll on a 7.6 kg lizi in one step; the robot spun up to NaN within 50 ms
    (twice: at 5.3 s and, with multi-point CCD off, at 42 s). CG needs no Hessian and converges
    on the same contacts (47 iterations, the robots stay on the ground) but costs ~10 % on every
    step, so it only redoes the steps Newton did not finish: the physics state before each step
    is kept (~2 us, 1 % of a 10-robot step) and restored for the redo. Normal steps are
    untouched, bit for bit.
    """

    SPEC = mujoco.mjtState.mjSTATE_FULLPHYSICS | mujoco.mjtState.mjSTATE_WARMSTART

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        self.state = np.empty(mujoco.mj_stateSize(model, self.SPEC))
        self.niter = data.solver_niter  # per island; zeroed by every step
        self.cap = int(model.opt.iterations)
        self.redone = 0  # steps redone with CG

    def save(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        mujoco.mj_getState(m, d, self.state, self.SPEC)

    def check(self, m: mujoco.MjModel, d: mujoco.MjData) -> None:
        """Redo the step just taken with CG if Newton ran to its iteration cap."""
        if not reached_cap(self.niter, self.cap) or m.opt.solver != mujoco.mjtSolver.mjSOL_NEWTON:
            return
        t = float(d.time)
        mujoco.mj_setState(m, d, self.state, self.SPEC)
        d.warning.number[:] = 0  # any warning came from the discarded step
        m.opt.solver = mujoco.mjtSolver.mjSOL_CG
        try:
            mujoco.mj_step(m, d)
        finally:
            m.opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
        self.redone += 1
        _log.debug("t = %.3f s: Newton did not converge; step redone with CG", t)


@numba.njit(cache=True)
def reached_cap(niter: np.ndarray, cap: int) -> bool:
    """Whether any island's solver ran ``cap`` iterations or more (``niter``: (I,) int32).

    Compiled: ``ndarray.max`` costs ~1-3 us per call, this ~0.3 us, after every step.
    """
    for k in range(niter.shape[0]):  # noqa: SIM110 (a plain loop compiles in numba)
        if niter[k] >= cap:
            return True
    return False


def physics_error(engine, t: float) -> SimulationError:
    """The error for the warning counters of ``engine.data`` (call when one is non-zero).

    Parameters
    ----------
    engine : the ``Engine`` whose last step tripped a counter. t : sim time at the start of
    that step, s.
    """
    m, d = engine.model, engine.data
    number, info = d.warning.number, d.warning.lastinfo
    where = f"physics instability at t = {t:.3f} s"
    if number[W.mjWARN_CONTACTFULL] or number[W.mjWARN_CNSTRFULL]:
        what = "contacts" if number[W.mjWARN_CONTACTFULL] else "constraints"
        return PhysicsBufferFull(
            f"physics at t = {t:.3f} s: MuJoCo ran out of memory for {what} ({d.ncon} "
            f"contacts, {d.nefc} constraint rows, arena of {m.narena} bytes) and dropped "
            "some, so bodies would pass through each other; try: fewer robots touching at "
            "once, or a larger arena (the world spec's memory size)"
        )
    if number[W.mjWARN_BADCTRL]:
        act = int(info[W.mjWARN_BADCTRL])
        dof = _actuator_dof(m, act)
        owner = _owner(engine, dof) if dof >= 0 else f"actuator '{m.actuator(act).name}'"
        return PhysicsInstability(
            f"{where}: NaN, infinite or huge command {float(d.ctrl[act])} on actuator "
            f"'{m.actuator(act).name}' ({owner}); likely cause: a NaN command from a "
            "controller or plugin; try: find what writes the actuator's control (the drive "
            "plugins ignore non-finite Twists) and guard it"
        )
    if number[W.mjWARN_INERTIA]:
        dof = int(info[W.mjWARN_INERTIA])
        return PhysicsInstability(
            f"{where}: the joint-space inertia is singular at {_owner(engine, dof)}; likely "
            "cause: bad inertia (a link with (near) zero mass or inertia on a moving joint); "
            "try: give the link a realistic <inertial> in its URDF/SDF"
        )
    for kind, quantity in _QUANTITY.items():
        if number[kind]:
            dof = int(info[kind])
            if kind == W.mjWARN_BADQPOS:
                dof = _qpos_dof(m, dof)
            cause, advice = likely_cause(engine, dof)
            return PhysicsInstability(
                f"{where}: NaN, infinite or huge {quantity} at {_owner(engine, dof)}; "
                f"likely cause: {cause}; try: {advice}"
            )
    raise AssertionError(f"physics_error called with clear counters {number}")


def _local(name: str) -> str:
    return name.split("/", 1)[1] if "/" in name else name


def _model_of_body(engine, body: int) -> tuple[int, str]:
    i = int(engine._body_model[body]) if body < len(engine._body_model) else -1
    if i < 0:
        return -1, ""
    name = engine._model_names[i]
    return i, f"{engine.models[name].kind if name in engine.models else 'model'} '{name}'"


def _owner(engine, dof: int) -> str:
    """``robot 'r8', body 'base_link', joint 'free' (floating base, rotation about x), DOF 83``."""
    m = engine.model
    body = int(m.dof_bodyid[dof])
    _, model = _model_of_body(engine, body)
    parts = [model] if model else []
    return ", ".join([*parts, f"body '{_local(m.body(body).name)}'", _joint_label(m, dof)])


def _joint_label(m: mujoco.MjModel, dof: int) -> str:
    """``joint 'free' (floating base, rotation about x), DOF 83``."""
    jnt = int(m.dof_jntid[dof])
    joint = f"joint '{_local(m.joint(jnt).name)}'"
    if m.jnt_type[jnt] == mujoco.mjtJoint.mjJNT_FREE:
        joint += f" (floating base, {_FREE_AXES[dof - m.jnt_dofadr[jnt]]})"
    return f"{joint}, DOF {dof}"


def _qpos_joints(m: mujoco.MjModel, qadr) -> np.ndarray:
    """The joints that hold position coordinates ``qadr`` (an index or an array of them)."""
    return np.maximum(np.searchsorted(m.jnt_qposadr, qadr, side="right") - 1, 0)


def _qpos_dof(m: mujoco.MjModel, qadr: int) -> int:
    """The first DOF of the joint that holds position coordinate ``qadr``."""
    return int(m.jnt_dofadr[int(_qpos_joints(m, qadr))])


def _actuator_dof(m: mujoco.MjModel, act: int) -> int:
    if m.actuator_trntype[act] != mujoco.mjtTrn.mjTRN_JOINT:
        return -1
    return int(m.jnt_dofadr[m.actuator_trnid[act, 0]])


def likely_cause(engine, dof: int) -> tuple[str, str]:
    """``(cause, what to try)`` for a blow-up at ``dof``, from the state of the failed step.

    The step's forward pass (controls, applied forces, contacts, actuator forces) stays valid
    after MuJoCo flags the acceleration; only the integrated positions and velocities are lost.
    The checks run from the most to the least certain: a non-finite control or applied force,
    a near-massless link under actuator force, a huge actuator force, a body already moving
    too fast before the step, a deep contact.
    """
    m, d = engine.model, engine.data
    model_i, _ = _model_of_body(engine, int(m.dof_bodyid[dof]))
    bad_ctrl = np.flatnonzero(~np.isfinite(d.ctrl))
    if bad_ctrl.size:
        a = int(bad_ctrl[0])
        return (
            f"NaN command ({d.ctrl[a]}) on actuator '{m.actuator(a).name}'",
            "find what writes the actuator's control (the drive plugins ignore non-finite "
            "Twists) and guard it",
        )
    bad_body = np.flatnonzero(~np.isfinite(d.xfrc_applied).all(axis=1))
    if bad_body.size or not np.isfinite(d.qfrc_applied).all():
        body = m.body(int(bad_body[0])).name if bad_body.size else "a joint (qfrc_applied)"
        return (
            f"NaN or infinite applied force on {body}",
            "check what applies forces (wrench services, plugins) for NaN",
        )
    dofs = _model_dofs(engine, model_i, dof)
    bad_state = _non_finite_state(engine, model_i, dofs)
    if bad_state is not None:
        return bad_state
    force = np.abs(np.nan_to_num(d.qfrc_actuator[dofs], nan=0.0, posinf=1e300))
    accel = force / np.maximum(m.dof_M0[dofs], 1e-300)
    k = int(np.argmax(accel))
    worst = int(dofs[k])
    if accel[k] > HUGE_ACCELERATION:
        body = int(m.dof_bodyid[worst])
        robot_mass = float(m.body_subtreemass[m.body_rootid[body]])
        joint = _local(m.joint(int(m.dof_jntid[worst])).name)
        link = _local(m.body(body).name)
        detail = (
            f"{force[k]:.3g} N m of actuator force on joint '{joint}' whose inertia is "
            f"{m.dof_M0[worst]:.3g} kg m^2 ({accel[k]:.3g} rad/s^2)"
        )
        if m.body_mass[body] < LIGHT_LINK_SHARE * robot_mass:
            return (
                f"bad inertia: link '{link}' of {m.body_mass[body]:.3g} kg (of "
                f"{robot_mass:.3g} kg) gets {detail}",
                f"give link '{link}' a realistic <inertial> mass and inertia",
            )
        return (
            f"huge actuator torque: {detail}",
            "lower the joint's effort/torque limit or the controller gains",
        )
    runaway = _runaway(engine, dofs, model_i)  # before contacts: it makes them deep
    if runaway is not None:
        return runaway
    pen = _deepest_contact(engine, model_i)
    if pen is not None:
        return pen
    return (
        "stiff constraint forces (contacts or joint limits) the solver could not resolve",
        "a smaller physics step, or check collision shapes and joint limits of this model",
    )


def _non_finite_state(engine, model_i: int, dofs: np.ndarray) -> tuple[str, str] | None:
    """A position or velocity that was already NaN or infinite before the step (the state
    `SolverGuard` kept): something wrote it into the state (a teleport, a plugin), the
    integration did not make it."""
    m = engine.model
    state = engine.solver_guard.state
    qpos, qvel = state[1 : 1 + m.nq], state[1 + m.nq : 1 + m.nq + m.nv]
    bad_vel = dofs[~np.isfinite(qvel[dofs])]
    mine = set(m.dof_jntid[dofs].tolist())  # every joint with coordinates has DOFs
    bad_pos = [j for j in _qpos_joints(m, np.flatnonzero(~np.isfinite(qpos))).tolist() if j in mine]
    if not bad_pos and not bad_vel.size:
        return None
    what = (
        f"position of joint '{_local(m.joint(bad_pos[0]).name)}'"
        if bad_pos
        else f"velocity of {_joint_label(m, int(bad_vel[0]))}"
    )
    return (
        f"non-finite state: the {what} was already NaN or infinite before this step",
        "find what set it (a set_model_state / teleport, a plugin writing qpos or qvel) and "
        "guard it",
    )


def _runaway(engine, dofs: np.ndarray, model_i: int) -> tuple[str, str] | None:
    """A model already moving too fast to integrate before the step (its velocities from the
    state `SolverGuard` kept): it was flung earlier and the blow-up is only the end of it."""
    m = engine.model
    qvel = engine.solver_guard.state[1 + m.nq : 1 + m.nq + m.nv][dofs]
    per_step = np.abs(np.nan_to_num(qvel, nan=np.inf)) * m.opt.timestep
    k = int(np.argmax(per_step))
    if per_step[k] <= RUNAWAY_STEP:
        return None
    dof = int(dofs[k])
    slide = m.jnt_type[m.dof_jntid[dof]] == mujoco.mjtJoint.mjJNT_SLIDE or (
        m.jnt_type[m.dof_jntid[dof]] == mujoco.mjtJoint.mjJNT_FREE
        and dof - m.jnt_dofadr[m.dof_jntid[dof]] < 3
    )
    unit = "m" if slide else "rad"
    touching = (engine.geom_model[engine.data.contact.geom[: engine.data.ncon]] == model_i).any()
    return (
        f"runaway motion: it was already moving at {abs(qvel[k]):.3g} {unit}/s on "
        f"{_joint_label(m, dof)} ({per_step[k]:.2g} {unit} per physics step) before this step"
        f"{'' if touching else ', touching nothing'}; something flung it earlier",
        "find when it was flung (its ground-truth pose or odometry over the last seconds), "
        "e.g. a collision or a force; a smaller physics step",
    )


def _model_dofs(engine, model_i: int, dof: int) -> np.ndarray:
    m = engine.model
    if model_i < 0:
        return np.array([dof])
    return np.flatnonzero(engine._body_model[m.dof_bodyid] == model_i)


def _deepest_contact(engine, model_i: int) -> tuple[str, str] | None:
    m, d = engine.model, engine.data
    if d.ncon == 0:
        return None
    geom = d.contact.geom[: d.ncon]
    dist = d.contact.dist[: d.ncon]
    mine = (
        (engine.geom_model[geom] == model_i).any(axis=1)
        if model_i >= 0
        else np.ones(len(geom), bool)
    )
    mine &= np.isfinite(dist)  # a NaN contact is not a measure of penetration
    if not mine.any():
        return None
    c = int(np.flatnonzero(mine)[np.argmin(dist[mine])])
    depth = -float(dist[c])
    if depth < DEEP_PENETRATION:
        return None
    a, b = (m.geom(int(g)).name for g in geom[c])
    return (
        f"contact penetration of {depth * 100:.1f} cm between '{a}' and '{b}'",
        "a smaller physics step or lower speeds/torques into obstacles; check the collision "
        "shapes of the bodies involved",
    )
