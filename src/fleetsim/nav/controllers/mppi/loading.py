"""Reading ``MPPIController/`` into its parameters and critics, with errors naming the key."""

from __future__ import annotations

import logging
from typing import Any

from fleetsim.errors import ParameterError, did_you_mean
from fleetsim.nav.controllers.mppi.critics import CRITICS, Critic
from fleetsim.nav.controllers.mppi.params import AckermannConstraints, MPPIParams
from fleetsim.runtime import load_params

_log = logging.getLogger("fleetsim.nav.mppi")
#: Nav2 resolves a critic name to the plugin ``mppi::critics::<name>``; both spellings work
CRITIC_PREFIX = "mppi::critics::"
SUB_NAMESPACES = ("AckermannConstraints", "TrajectoryVisualizer")


def critic_class(name: str, where: str) -> type[Critic]:
    short = name.removeprefix(CRITIC_PREFIX)
    if short not in CRITICS:
        raise ParameterError(
            f"{where}: parameter 'critics' names '{name}', which is not a critic"
            f"{did_you_mean(short, CRITICS)}; known: {', '.join(CRITICS)}"
        )
    return CRITICS[short]


def load_mppi(
    ns: dict[str, Any] | None, where: str = "MPPIController"
) -> tuple[MPPIParams, AckermannConstraints, list[Critic]]:
    """(controller parameters, Ackermann constraints, enabled critics in order) from a
    namespace dict; a `ParameterError` names the parameter (and its file, when known)."""
    ns = ns or {}
    listed = ns.get("critics") or []
    names = [str(n) for n in listed] if isinstance(listed, list | tuple) else []
    ignore = frozenset((*CRITICS, *SUB_NAMESPACES, *names))
    p = load_params(MPPIParams, ns, where, ignore=ignore, logger=_log)
    if p.vx_min > p.vx_max:
        raise ParameterError(f"{where}: parameter 'vx_min' = {p.vx_min} exceeds vx_max {p.vx_max}")
    if p.enforce_path_inversion:
        raise ParameterError(
            f"{where}: parameter 'enforce_path_inversion' = true is not available (navfn plans "
            "have no cusps); set it false"
        )
    if not p.critics:
        raise ParameterError(
            f"{where}: parameter 'critics' is empty, so nothing steers the robot; list some, "
            f"e.g. [ConstraintCritic, CostCritic, GoalCritic, GoalAngleCritic, PathAlignCritic, "
            f"PathFollowCritic, PathAngleCritic, PreferForwardCritic]"
        )
    ack = load_params(
        AckermannConstraints, ns.get("AckermannConstraints") or {}, f"{where}/AckermannConstraints"
    )
    critics = []
    for name in p.critics:
        cls = critic_class(str(name), where)
        sub = ns.get(name) or ns.get(str(name).removeprefix(CRITIC_PREFIX)) or {}
        if not isinstance(sub, dict):
            raise ParameterError(f"{where}/{name}: the critic's parameters must be a mapping")
        cparams = load_params(cls.Params, sub, f"{where}/{name}", logger=_log)
        if cparams.enabled:
            critics.append(cls(cparams))
    for key, value in ns.items():
        if key in CRITICS and key not in p.critics and isinstance(value, dict):
            _log.warning("%s: '%s' has parameters but is not in 'critics'; unused", where, key)
    return p, ack, critics
