"""Link attacher world plugin (``libgazebo_ros_link_attacher.so``).

``attach(model1, link1, model2, link2)`` fixes two links of two models together in their
current relative pose (a MuJoCo weld constraint); ``detach`` releases them. Requests are queued
and applied inside the next simulation step, as the Gazebo plugin does.
"""

from __future__ import annotations

import mujoco
import numpy as np

from fleetsim.errors import SimulationError

FILENAME = "libgazebo_ros_link_attacher.so"


def _eq_name(m1: str, l1: str, m2: str, l2: str) -> str:
    return f"attach:{m1}/{l1}|{m2}/{l2}"


class LinkAttacher:
    def __init__(self) -> None:
        self.pending: list[tuple[str, tuple[str, str, str, str]]] = []
        self.joints: set[tuple[str, str, str, str]] = set()

    def _check(self, engine, m1: str, l1: str, m2: str, l2: str) -> None:
        engine.link_id(m1, l1)
        engine.link_id(m2, l2)
        if m1 == m2:
            raise SimulationError(f"cannot attach model '{m1}' to itself")

    def attach(self, engine, m1: str, l1: str, m2: str, l2: str) -> None:
        """Queue a fixed joint between ``m1/l1`` and ``m2/l2`` (applied at the next step); a
        pair already attached stays as it is (the Gazebo plugin answers ok then too)."""
        self._check(engine, m1, l1, m2, l2)
        key = (m1, l1, m2, l2)
        if key in self.joints and ("detach", key) not in self.pending:
            return  # already held: the Gazebo plugin re-attaches its cached joint and says ok
        self.pending.append(("attach", key))

    def detach(self, engine, m1: str, l1: str, m2: str, l2: str) -> None:
        """Queue the release of an attachment made by ``attach``."""
        key = (m1, l1, m2, l2)
        if key not in self.joints and ("attach", key) not in self.pending:
            raise SimulationError(f"'{m1}/{l1}' and '{m2}/{l2}' are not attached")
        self.pending.append(("detach", key))

    def control(self, engine, t: float) -> None:
        if not self.pending:
            return
        todo, self.pending = self.pending, []
        for op, key in todo:
            if op == "attach":
                if key not in self.joints:
                    self._add(engine, key)
            else:
                eq = engine.spec.equality(_eq_name(*key))
                if eq is not None:
                    engine.spec.delete(eq)
                self.joints.discard(key)
        engine._compile()

    def _add(self, engine, key) -> None:
        m1, l1, m2, l2 = key
        d = engine.data
        b1, b2 = engine.link_id(m1, l1), engine.link_id(m2, l2)
        # pose of body2 in body1's frame
        qi = np.zeros(4)
        mujoco.mju_negQuat(qi, d.xquat[b1])
        rel_p = np.zeros(3)
        mujoco.mju_rotVecQuat(rel_p, d.xpos[b2] - d.xpos[b1], qi)
        rel_q = np.zeros(4)
        mujoco.mju_mulQuat(rel_q, qi, d.xquat[b2])
        eq = engine.spec.add_equality(
            name=_eq_name(*key),
            type=mujoco.mjtEq.mjEQ_WELD,
            objtype=mujoco.mjtObj.mjOBJ_BODY,
            name1=f"{m1}/{l1}",
            name2=f"{m2}/{l2}",
        )
        data = np.zeros(12)  # anchor (3), relpose pos (3) quat (4), torquescale, unused
        data[3:6] = rel_p
        data[6:10] = rel_q
        data[10] = 1.0
        eq.data = data
        eq.solref = [0.005, 1.0]
        self.joints.add(key)

    def forget_model(self, engine, name: str) -> None:
        """Drop attachments involving a model about to be deleted."""
        for key in list(self.joints):
            if name in (key[0], key[2]):
                eq = engine.spec.equality(_eq_name(*key))
                if eq is not None:
                    engine.spec.delete(eq)
                self.joints.discard(key)
        self.pending = [(op, k) for op, k in self.pending if name not in (k[0], k[2])]
