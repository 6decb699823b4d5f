"""``fleetsim node run module:Class``: one node in its own process, joined to a simulation.

The process gets its own `Runtime` on the simulation's ``/clock`` (`ZenohBridge` with
``follow_clock``), a copy of the simulation's parameter tree (so the node reads the same YAML
the launch file loaded), the ``--param`` values in the node's private namespace and the
``--remap`` rules, and runs until the simulation goes away or it is stopped.
"""

from __future__ import annotations

import importlib
import logging
import threading
from collections.abc import Iterable, Mapping
from typing import Any

import yaml

from fleetsim.errors import LaunchError
from fleetsim.transport.keys import default_endpoint
from fleetsim.transport.paramserver import request_param

_log = logging.getLogger("fleetsim.transport")


def parse_assignments(items: Iterable[str], what: str) -> dict[str, Any]:
    """``["k:=v", ...]`` as a dict; values are read as YAML (``2`` an int, ``[1, 2]`` a list)
    for ``--param``, kept as text for ``--remap``."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition(":=")
        if not sep or not key.strip():
            raise LaunchError(f"{what} {item!r} must look like NAME:=VALUE")
        if what == "--param":
            try:
                out[key.strip()] = yaml.safe_load(value) if value.strip() else ""
            except yaml.YAMLError as e:
                problem = getattr(e, "problem", None) or str(e).splitlines()[0]
                raise LaunchError(f"{what} {item!r}: the value is not YAML: {problem}") from None
        else:
            out[key.strip()] = value.strip()
    return out


def load_node_class(spec: str) -> type:
    """The class named by ``module:Class`` (``my_pkg.nodes:Follower``)."""
    from fleetsim.runtime import Node

    module, sep, attr = spec.partition(":")
    if not sep or not module or not attr:
        raise LaunchError(f"node {spec!r} must be given as module:Class (my_pkg.nodes:Follower)")
    from fleetsim.launch.registry import import_beside

    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as e:
        mod = import_beside(module, e, "")  # a module in the working directory, as rosrun's
        if mod is None:
            raise LaunchError(
                f"node {spec!r}: cannot import module {e.name!r} (looked on the Python path "
                "and in the working directory; set PYTHONPATH for elsewhere)"
            ) from None
    cls = getattr(mod, attr, None)
    if not (isinstance(cls, type) and issubclass(cls, Node)):
        raise LaunchError(f"node {spec!r}: {module} has no Node subclass named {attr!r}")
    return cls


def run_node(
    spec: str | type,
    namespace: str = "/",
    *,
    name: str | None = None,
    params: Mapping[str, Any] | None = None,
    remaps: Mapping[str, str] | None = None,
    connect: str | None = None,
    domain: str | int | None = None,
    seed: int = 0,
    until: float | None = None,
    stop: threading.Event | None = None,
    clock_timeout: float = 5.0,
) -> None:
    """Run one node on a remote simulation's clock until ``until`` (sim s), ``stop``, or the
    simulation goes away (then `TransportError`)."""
    from fleetsim.runtime import Runtime
    from fleetsim.transport.bridge import ZenohBridge

    cls = load_node_class(spec) if isinstance(spec, str) else spec
    endpoint = connect or default_endpoint()
    rt = Runtime(seed=seed)
    bridge = ZenohBridge(
        rt,
        mode="client",
        connect=[endpoint],
        domain=domain,
        follow_clock=True,
        clock_timeout=clock_timeout,
        role="node",
    )
    try:
        tree = request_param(bridge.session, bridge.keys, "dump", "/", timeout=clock_timeout)
        if isinstance(tree, dict):
            rt.params.set("/", tree)
        kwargs: dict[str, Any] = {"namespace": namespace, "remaps": remaps, "params": params}
        if name is not None:
            kwargs["name"] = name
        node = cls(rt, **kwargs)
        _log.info("%s joined the simulation at %s (t = %.3f s)", node.full_name, endpoint, rt.now())
        bridge.run_following(until=until, stop=stop)
    finally:
        rt.shutdown()
