"""The ``controller_manager`` of one robot, as gazebo_ros_control starts it in the simulator.

It lives in the robot's namespace (``/<ns>/controller_manager``) and serves
``list_controllers``, ``list_controller_types``, ``load_controller``, ``unload_controller`` and
``switch_controller`` there. Loading reads ``/<ns>/<name>/type`` and the rest of the
controller's YAML; running controllers are updated every physics step (the plugin's update hook)
with the simulator's time. The Python methods (``load``, ``switch``, ``unload``) raise
``ControlError`` naming the controller; the services answer ``ok: false`` and log that error,
as ros_control does.
"""

from __future__ import annotations

from fleetsim.control.controllers import CONTROLLER_TYPES, controller_class
from fleetsim.control.hardware import INTERFACES, SimRobotHW
from fleetsim.errors import ControlError, FleetsimError, did_you_mean
from fleetsim.msgs import controller_manager_msgs as cm
from fleetsim.runtime import Node
from fleetsim.runtime import names as rnames


class ControllerManager(Node):
    """Controllers of one robot's ros_control hardware (``SimRobotHW``).

    Parameters
    ----------
    sim : the ``Simulator`` node (its engine and time offset).
    plugin : the robot's ``JointActuationPlugin``.
    """

    def __init__(self, runtime, namespace: str, *, sim, plugin) -> None:
        super().__init__(runtime, "controller_manager", namespace)
        self.sim = sim
        self.hw = SimRobotHW(plugin, sim.engine)
        self.controllers: dict = {}
        self._last_t: float | None = None
        plugin.add_update_hook(self._update)
        self.create_service(cm.ListControllers, "~list_controllers", self._srv_list)
        self.create_service(cm.ListControllerTypes, "~list_controller_types", self._srv_types)
        self.create_service(cm.LoadController, "~load_controller", self._srv_load)
        self.create_service(cm.UnloadController, "~unload_controller", self._srv_unload)
        self.create_service(cm.SwitchController, "~switch_controller", self._srv_switch)

    # ------------------------------------------------------------------ python API
    def load(self, name: str):
        """Load controller ``name`` from its parameters ``/<ns>/<name>``; returns it."""
        where = f"{self.full_name}: controller '{name}'"
        if name in self.controllers:
            raise ControlError(f"{where} was already loaded")
        key = rnames.join(self.namespace, name)
        type_name = self.runtime.params.get(f"{key}/type", None)
        if not type_name:
            raise ControlError(
                f"{where}: the type was not specified; did you load the controller "
                f"configuration on the parameter server (namespace: '{key}')?"
            )
        cls = controller_class(str(type_name), where)
        ctrl = cls(self.runtime, name, self.namespace, hw=self.hw, type_name=str(type_name))
        self.controllers[name] = ctrl
        return ctrl

    def unload(self, name: str) -> None:
        ctrl = self._get(name)
        if ctrl.running:
            raise ControlError(f"{self.full_name}: controller '{name}' is running; stop it first")
        ctrl.destroy()
        del self.controllers[name]

    def switch(self, start=(), stop=(), strict: bool = True) -> None:
        """Stop, then start controllers; with ``strict`` any unknown name fails the switch."""
        start, stop = list(start), list(stop)
        for name in start + stop:
            if name not in self.controllers:
                if strict:
                    self._get(name)
                self.get_logger().warning("controller '%s' is not loaded; skipped", name)
        start = [n for n in start if n in self.controllers]
        stop = [n for n in stop if n in self.controllers]
        owners = {
            j: n
            for n, c in self.controllers.items()
            if c.running and n not in stop
            for j in c.claimed()
        }
        for n in start:
            if self.controllers[n].running:
                continue
            for j in self.controllers[n].claimed():
                if j in owners and owners[j] != n:
                    raise ControlError(
                        f"{self.full_name}: cannot start '{n}': joint '{j}' is already "
                        f"claimed by running controller '{owners[j]}' (stop it in the same switch)"
                    )
                owners[j] = n
        t = self.sim_time()
        for n in stop:
            c = self.controllers[n]
            if c.running:
                c.stopping(t)
                c.running = False
        for n in start:
            c = self.controllers[n]
            if not c.running:
                c.starting(t)
                c.running = True

    def sim_time(self) -> float:
        return self.sim.engine.time + self.sim.offset

    def _get(self, name: str):
        if name not in self.controllers:
            raise ControlError(
                f"{self.full_name}: controller '{name}' is not loaded"
                f"{did_you_mean(name, self.controllers)}"
            )
        return self.controllers[name]

    def _update(self, plugin, engine, t: float) -> None:
        dt = engine.model.opt.timestep
        now = t + self.sim.offset
        for c in self.controllers.values():
            if c.running:
                c.update(now, dt)

    def destroy(self) -> None:
        for c in list(self.controllers.values()):
            c.destroy()
        self.controllers.clear()
        super().destroy()

    # ------------------------------------------------------------------ services
    def _ok(self, fn, *a) -> bool:
        try:
            fn(*a)
        except FleetsimError as e:
            self.get_logger().error("%s", e)
            return False
        return True

    def _srv_list(self, req):
        out = []
        for n, c in self.controllers.items():
            res = []
            if c.claimed():
                res = [cm.HardwareInterfaceResources(INTERFACES[c.interface], c.claimed())]
            out.append(
                cm.ControllerState(
                    name=n,
                    state="running" if c.running else "stopped",
                    type=c.type_name,
                    claimed_resources=res,
                )
            )
        return cm.ListControllersResponse(controller=out)

    def _srv_types(self, req):
        types = sorted(CONTROLLER_TYPES)
        return cm.ListControllerTypesResponse(
            types=types, base_classes=["controller_interface::ControllerBase"] * len(types)
        )

    def _srv_load(self, req):
        return cm.LoadControllerResponse(ok=self._ok(self.load, req.name))

    def _srv_unload(self, req):
        return cm.UnloadControllerResponse(ok=self._ok(self.unload, req.name))

    def _srv_switch(self, req):
        strict = req.strictness != cm.SwitchControllerRequest.BEST_EFFORT
        ok = self._ok(self.switch, list(req.start_controllers), list(req.stop_controllers), strict)
        return cm.SwitchControllerResponse(ok=ok)
