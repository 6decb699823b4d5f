"""``controller_manager/spawner``: load and start controllers at launch, stop them at shutdown.

Arguments as the ROS 1 spawner takes them: controller names, ``--stopped`` (load only),
``--shutdown-timeout T`` (accepted; nothing blocks here), ``--timeout T`` (how long to wait for
the controller_manager, default 30 s of sim time), ``--namespace NS`` (the controller_manager's
namespace, default the node's). It waits for ``<ns>/controller_manager/load_controller`` as the
spawner does, then loads each controller and starts them together. A failure is logged with
the controller_manager's reason and the spawner gives up (``failed`` says why), as the ROS
spawner exits.
"""

from __future__ import annotations

from fleetsim.errors import ControlError, FleetsimError
from fleetsim.msgs import controller_manager_msgs as cm
from fleetsim.runtime import Node
from fleetsim.runtime import names as rnames

RETRY = 0.1  # s of sim time between looks for the controller_manager


def parse_spawner_args(args: list[str], where: str) -> dict:
    out = {"controllers": [], "stopped": False, "timeout": 30.0, "namespace": None}
    i = 0
    while i < len(args):
        a = args[i]
        if a == "--stopped":
            out["stopped"] = True
        elif a in ("--shutdown-timeout", "--timeout", "--namespace"):
            if i + 1 >= len(args):
                raise ControlError(f"{where}: '{a}' needs a value")
            v = args[i + 1]
            if a == "--namespace":
                out["namespace"] = v
            else:
                try:
                    t = float(v)
                except ValueError:
                    raise ControlError(f"{where}: '{a}' needs a number, got '{v}'") from None
                if a == "--timeout":
                    out["timeout"] = t
            i += 1
        elif a.startswith("-"):
            raise ControlError(
                f"{where}: unknown option '{a}'; the spawner takes controller names, --stopped, "
                "--shutdown-timeout T, --timeout T, --namespace NS"
            )
        else:
            out["controllers"].append(a)
        i += 1
    if not out["controllers"]:
        raise ControlError(f'{where}: no controller names given (args="name1 name2")')
    return out


class Spawner(Node):
    def __init__(
        self, runtime, name: str = "controller_spawner", namespace: str = "/", **kw
    ) -> None:
        super().__init__(runtime, name, namespace, **kw)
        opts = parse_spawner_args(self.args, self.full_name)
        self.controllers = opts["controllers"]
        self.stopped = opts["stopped"]
        self.timeout = opts["timeout"]
        ns = opts["namespace"] or self.namespace
        self.cm = rnames.join(rnames.resolve(ns, self.namespace), "controller_manager")
        self.loaded: list[str] = []
        self.done = False
        self.failed = ""
        self.t0 = self.now()
        self.timer = self.create_timer(RETRY, self._try)
        runtime.on_shutdown(self._shutdown)

    def _call(self, srv, what: str, req):
        return self.runtime.graph.call_service(f"{self.cm}/{what}", srv, req)

    def _try(self) -> None:
        if self.done or self.failed:
            return
        if f"{self.cm}/load_controller" not in self.runtime.graph.services:
            if self.now() - self.t0 > self.timeout:
                self._fail(
                    f"controller spawner couldn't find the expected controller_manager ROS "
                    f"interface ({self.cm}/load_controller) within {self.timeout:g} s"
                )
            return
        try:
            for name in self.controllers:
                if name in self.loaded:
                    continue
                if not self._call(
                    cm.LoadController, "load_controller", cm.LoadControllerRequest(name)
                ).ok:
                    return self._fail(f"Failed to load {name}")
                self.loaded.append(name)
                self.get_logger().info("Loaded %s", name)
            if not self.stopped:
                req = cm.SwitchControllerRequest(
                    start_controllers=self.controllers, strictness=cm.SwitchControllerRequest.STRICT
                )
                if not self._call(cm.SwitchController, "switch_controller", req).ok:
                    return self._fail(f"Failed to start controllers: {', '.join(self.controllers)}")
                self.get_logger().info(
                    "Controller Spawner: Loaded controllers: %s", ", ".join(self.controllers)
                )
        except FleetsimError as e:
            return self._fail(str(e))
        self.done = True
        self.timer.cancel()

    def _fail(self, why: str) -> None:
        self.failed = why
        self.timer.cancel()
        self.get_logger().error("%s", why)

    def _shutdown(self) -> None:
        """Stop and unload what this spawner started (the spawner's shutdown hook)."""
        if f"{self.cm}/switch_controller" not in self.runtime.graph.services:
            return
        try:
            self._call(
                cm.SwitchController,
                "switch_controller",
                cm.SwitchControllerRequest(
                    stop_controllers=self.loaded, strictness=cm.SwitchControllerRequest.BEST_EFFORT
                ),
            )
            for name in self.loaded:
                self._call(
                    cm.UnloadController, "unload_controller", cm.UnloadControllerRequest(name)
                )
        except FleetsimError as e:
            self.get_logger().warning("shutdown: %s", e)
