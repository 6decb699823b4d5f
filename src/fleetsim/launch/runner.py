"""Running a `LaunchPlan`: one runtime, parameters first, then every node in file order.

A session either hosts the simulation (and, with ``listen``, lets tools and other processes
join it) or, with ``connect``, joins a simulation running elsewhere, as roslaunch does on a
second machine: its runtime follows the simulation's ``/clock``, starts from a copy of the
simulation's parameters, sets the plan's parameters there too (the master's tree, for every
process to read) and its nodes talk to the others over Zenoh (services of other processes,
e.g. ``/gazebo/spawn_urdf_model``, are reachable as local ones).

Viewer nodes (``rviz``, ``gazebo_ros/gzclient``) open the Foxglove live view when the run has
one (``--viz``) and are otherwise noted and skipped: fleetsim runs headless.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fleetsim.errors import FleetsimError, LaunchError
from fleetsim.launch.model import LaunchPlan, NodeSpec
from fleetsim.launch.monitor import RunMonitor
from fleetsim.launch.registry import resolve_node
from fleetsim.runtime import Runtime

_log = logging.getLogger("fleetsim.launch")

#: nodes that show things to people: the live view stands in for all of them
VIEWERS = {("rviz", "rviz"), ("gazebo_ros", "gzclient"), ("rqt_gui", "rqt_gui")}


def load_plan(path: str | Path, args: dict[str, str] | None = None, seed: int = 0) -> LaunchPlan:
    """Read a launch file of either kind (``.launch``/``.xml`` or ``.yaml``)."""
    from fleetsim.launch.xml_frontend import load_xml
    from fleetsim.launch.yaml_frontend import load_yaml

    path = Path(path)
    if not path.is_file():
        raise LaunchError(f"launch file {path} does not exist")
    if path.suffix in (".yaml", ".yml"):
        return load_yaml(path, args, seed=seed)
    return load_xml(path, args, seed=seed)


@dataclass
class LaunchSession:
    """A plan's nodes, alive in one runtime."""

    plan: LaunchPlan
    seed: int = 0
    viz: bool = False
    record: str | Path | None = None
    #: Zenoh endpoint the run listens on for tools and other processes; None: no bridge
    listen: str | None = None
    #: Zenoh endpoint of a simulation to join instead of hosting one (see the module docstring)
    connect: str | None = None
    runtime: Runtime = field(init=False)
    nodes: dict[str, Any] = field(default_factory=dict, init=False)
    skipped: list[str] = field(default_factory=list, init=False)
    recorder: Any = field(default=None, init=False)
    live: Any = field(default=None, init=False)
    bridge: Any = field(default=None, init=False)
    monitor: RunMonitor = field(init=False)

    def __post_init__(self) -> None:
        self.runtime = Runtime(self.seed)
        try:
            self._start()
        except BaseException:
            self.close()
            raise

    def _start(self) -> None:
        rt = self.runtime
        if self.connect is not None:
            self._join(self.connect)
        else:
            self.plan.apply_params(rt.params)
        if self.record is not None:
            from fleetsim.record import Recorder

            self.recorder = Recorder(rt, self.record)
        for note in self.plan.notes:
            _log.info(note)
        for spec in self.plan.nodes:
            self._start_node(spec)
        if not self.plan.nodes and not self.plan.params and self.connect is None:
            # roslaunch runs such a file without a word; mostly it is an if/unless whose
            # argument was misspelt (a sim_type no group matches); a file that only sets
            # parameters (an upload.launch) is left alone
            _log.warning(
                "the launch file starts no node and sets no parameter: check its if/unless "
                "conditions and the arguments they read"
            )
        self.monitor = RunMonitor(rt, self.plan, self.nodes)
        if self.listen is not None and self.connect is None:
            from fleetsim.transport import ZenohBridge

            self.bridge = ZenohBridge(rt, listen=[self.listen])
            _log.info(f"listening for fleetsim tools on {self.listen}")

    def _join(self, endpoint: str) -> None:
        """Follow the simulation at ``endpoint``: its clock, its parameters plus the plan's."""
        from fleetsim.transport import ZenohBridge
        from fleetsim.transport.paramserver import request_param

        rt = self.runtime
        self.bridge = ZenohBridge(
            rt, mode="client", connect=[endpoint], follow_clock=True, role="node"
        )
        session, keys = self.bridge.session, self.bridge.keys
        tree = request_param(session, keys, "dump", "/", timeout=5.0)
        if isinstance(tree, dict):
            rt.params.set("/", tree)
        own = self.plan.param_tree()
        for name in own.names():
            if name != "/":  # names() of an empty tree
                value = own.get(name)
                rt.params.set(name, value)
                request_param(session, keys, "set", name, value, timeout=5.0)
        _log.info(f"joined the simulation at {endpoint} (t = {rt.now():.3f} s)")

    def _start_node(self, spec: NodeSpec) -> None:
        if (spec.pkg, spec.type) in VIEWERS:
            if self.viz and self.live is None:
                from fleetsim.viz import LiveServer

                self.live = LiveServer(self.runtime)
                _log.info(f"{spec.full_name}: live view at {self.live.url} (open it in Foxglove)")
            elif not self.viz:
                self.skipped.append(spec.full_name)
                _log.info(f"{spec.full_name} ({spec.pkg}/{spec.type}) skipped: run with --viz")
            return
        cls = resolve_node(spec.pkg, spec.type, spec.source)
        try:
            node = cls(
                self.runtime,
                name=spec.name,
                namespace=spec.namespace,
                remaps=spec.remaps,
                args=spec.args,
            )
        except FleetsimError as e:
            raise LaunchError(f"{spec.source}: node {spec.full_name} failed to start: {e}") from e
        self.nodes[spec.full_name] = node

    def run(
        self,
        duration: float | None = None,
        until_goals: bool = False,
        rate=None,
        stop: threading.Event | None = None,
    ) -> None:
        """Run for ``duration`` s of sim time, or until every robot's goals are done.

        A session that joined a simulation runs with its clock (``rate`` does not apply) and
        may also run until ``stop`` is set (neither duration nor goals given) or the
        simulation goes away (`TransportError`).
        """
        until = self.monitor.all_goals_done if until_goals else None
        if self.connect is None:
            if duration is None and until is None:
                raise LaunchError("give a duration (--duration S) or --until-goals")
            self.runtime.run(duration=duration, until=until, rate=rate)
            return
        rt = self.runtime
        end = None if duration is None else rt.now() + duration
        while not (stop is not None and stop.is_set()) and (end is None or rt.now() < end - 1e-9):
            step = rt.now() + 0.5  # check the goals every half second of sim time
            self.bridge.run_following(until=step if end is None else min(step, end), stop=stop)
            if until is not None and until():
                return

    def close(self) -> None:
        """Shut the run down; the recording is finalised whatever happened."""
        errors = []
        closers = (
            self.runtime.shutdown,
            self._close_bridge,
            self._close_recorder,
            self._close_live,
        )
        for closer in closers:
            try:
                closer()
            except Exception as e:  # keep closing the rest
                errors.append(e)
        if errors:
            raise errors[0]

    def _close_bridge(self) -> None:
        if self.bridge is not None:
            self.bridge.close()

    def _close_recorder(self) -> None:
        if self.recorder is not None:
            self.recorder.close()

    def _close_live(self) -> None:
        if self.live is not None:
            self.live.close()

    def __enter__(self) -> LaunchSession:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            self.close()
        except Exception as e:
            if exc is None:
                raise
            # the error that ended the run (e.g. a physics instability) is the one to report
            _log.error(f"while shutting down after '{exc}': {e}")
