"""roslaunch XML's process elements: ``<node>``, ``<test>`` and ``<machine>``, as a mixin of the
XML loader, with roslaunch's checks (``xmlloader.py`` and ``core.Node``).

fleetsim runs every node in this process, so two things roslaunch does are errors here:
``launch-prefix`` (gdb, valgrind, xterm wrappers) and nodes placed on a ``<machine>`` whose
address is another host (start them there with ``fleetsim launch --connect`` instead). A
machine on this host is accepted as roslaunch accepts it.
"""

from __future__ import annotations

import contextlib
import shlex
import socket
from functools import cache
from typing import Any

import yaml

from fleetsim.errors import LaunchError
from fleetsim.launch.model import NodeSpec, ParamOp
from fleetsim.runtime import names

_OUTPUTS = ("log", "screen")
_CWDS = {"ROS_HOME": "ROS_HOME", "ros_home": "ROS_HOME", "node": "node"}
_MACHINE_DEFAULTS = ("true", "false", "never")


@cache
def _this_host() -> frozenset[str]:
    hosts = {"localhost", "::1", "0.0.0.0"}
    for get in (socket.gethostname, socket.getfqdn):
        with contextlib.suppress(OSError):  # a host without a name
            hosts.add(get().lower())
    return frozenset(hosts)


def is_local_address(address: str) -> bool:
    """True for this host's names and loopback addresses."""
    a = address.strip().lower()
    return a in _this_host() or a.startswith("127.")


class NodeElements:
    """``<node>``, ``<test>``, ``<machine>``; mixed into `XmlLoader`."""

    def _float(self, el, attrs, scope, key: str, default: float) -> float:
        if key not in attrs:
            return default
        try:
            return float(attrs[key])
        except ValueError:
            raise LaunchError(
                f"{self._where(scope, el, key)}: invalid float value {attrs[key]!r}"
            ) from None

    def _machine_of(self, el, attrs, scope) -> str:
        name = attrs.get("machine") or self.default_machine
        if not name:
            return ""
        where = self._where(scope, el, "machine")
        if name not in self.machines:
            raise LaunchError(
                f"{where}: unknown machine '{name}'; declare it with <machine name=... "
                "address=.../> before the node"
            )
        address = self.machines[name]
        if not is_local_address(address):
            raise LaunchError(
                f"{where}: machine '{name}' is at {address}; fleetsim does not start nodes on "
                "other hosts over ssh. Run them there with `fleetsim launch --connect` (or "
                "`fleetsim node run`) and drop machine= here"
            )
        return name

    def _node(self, el, attrs, scope: Any) -> None:
        self._require(el, attrs, scope, "pkg", "type", "name")
        where = self._where(scope, el)
        names.validate_base_name(attrs["name"], f" ({where})")
        ns = self._ns_join(scope.ns, attrs.get("ns"), self._where(scope, el, "ns"))
        try:
            args = shlex.split(attrs.get("args", ""))
        except ValueError as e:
            raise LaunchError(f"{where}: args do not parse: {e}") from None
        args, arg_remaps, arg_params = _command_line_names(args, where)
        if attrs.get("launch-prefix", "").strip():
            raise LaunchError(
                f"{self._where(scope, el, 'launch-prefix')}: fleetsim runs nodes in this "
                f"process and does not support launch-prefix ({attrs['launch-prefix']!r}); "
                "remove it"
            )
        output = attrs.get("output", "log")
        if output not in _OUTPUTS:
            raise LaunchError(
                f"{self._where(scope, el, 'output')}: output must be one of 'log', 'screen', "
                f"got {output!r}"
            )
        cwd = attrs.get("cwd", "ROS_HOME")
        if cwd not in _CWDS:
            raise LaunchError(
                f"{self._where(scope, el, 'cwd')}: cwd must be one of 'ROS_HOME', 'node', "
                f"got {cwd!r}"
            )
        respawn = self._flag(el, attrs, scope, "respawn")
        required = self._flag(el, attrs, scope, "required")
        if respawn and required:
            raise LaunchError(f"{where}: respawn and required cannot both be set to true")
        node = NodeSpec(
            pkg=attrs["pkg"],
            type=attrs["type"],
            name=attrs["name"],
            namespace=ns,
            args=args,
            # roslaunch puts every <remap> (the group's and the node's) after the args on the
            # command line: they win
            remaps={**arg_remaps, **scope.remaps},
            output=output,
            respawn=respawn,
            respawn_delay=self._float(el, attrs, scope, "respawn_delay", 0.0),
            required=required,
            cwd=_CWDS[cwd],
            machine=self._machine_of(el, attrs, scope),
            env=dict(scope.env),
            source=f"{where} (included from {scope.included_from})"
            if scope.included_from
            else where,
        )
        private = names.join(ns, node.name)
        if self._flag(el, attrs, scope, "clear_params"):
            self.plan.params.append(ParamOp("clear", private, source=where))
        inner = scope.child(node=node, ns=ns, pending=[])
        self._children(el, inner, {"remap", "param", "rosparam", "env"})
        # roslaunch sets the scope's ~params, then the node's own <param>s, after its
        # <rosparam>s (xmlloader: "evaluate all ~params in context")
        for name, value, pwhere in scope.private:
            full = names.resolve(name.lstrip("~"), private, where=f" ({pwhere})")
            self.plan.params.append(ParamOp("set", full, value, pwhere))
        self.plan.params.extend(inner.pending)
        # _param:=value on the command line: set by the node itself as it starts, after all
        # of the launch file's parameters (XmlLoader.load appends them last)
        for key, value in arg_params:
            self.arg_params.append(ParamOp("set", names.join(private, key), value, where))
        self.plan.nodes.append(node)

    def _test(self, el, attrs, scope) -> None:
        where = self._where(scope, el)
        self._require(el, attrs, scope, "pkg", "type", "test-name")
        if "time-limit" in attrs:
            limit = self._float(el, attrs, scope, "time-limit", 0.0)
            if limit <= 0.0:
                raise LaunchError(f"{where}: 'time-limit' must be a positive number")
        if attrs.get("retry"):
            try:
                int(attrs["retry"])
            except ValueError:
                raise LaunchError(
                    f"{where}: 'retry' must be a number: {attrs['retry']!r}"
                ) from None
        self.plan.notes.append(
            f"{where}: <test> skipped (roslaunch does not run tests; rostest does)"
        )

    def _machine(self, el, attrs, scope) -> None:
        where = self._where(scope, el)
        old = [k for k in ("ros-root", "ros-package-path", "ros-ip", "ros-hostname") if k in attrs]
        if old:
            raise LaunchError(
                f"{where}: <machine> attributes {old} are not supported since ROS Fuerte; "
                "use env-loader instead"
            )
        self._require(el, attrs, scope, "name", "address")
        for child in el:
            if isinstance(child.tag, str):
                raise LaunchError(
                    f"{self._where(scope, child)}: <{child.tag}> inside <machine> is not "
                    "supported (since ROS Fuerte: use env-loader)"
                )
        try:
            int(attrs.get("ssh-port") or "22")
        except ValueError:
            raise LaunchError(f"{where}: 'ssh-port' must be a number") from None
        if "timeout" in attrs:
            timeout = self._float(el, attrs, scope, "timeout", 0.0)
            if timeout <= 0.0:
                raise LaunchError(f"{where}: 'timeout' must be a positive number")
        default = (attrs.get("default") or "false").lower()
        if default not in _MACHINE_DEFAULTS:
            raise LaunchError(
                f"{where}: 'default' must be true, false or never, got {attrs['default']!r}"
            )
        self.machines[attrs["name"]] = attrs["address"]
        if default == "true":
            self.default_machine = attrs["name"]


def _command_line_names(
    args: list[str], where: str
) -> tuple[list[str], dict[str, str], list[tuple[str, Any]]]:
    """Split a node's ``args`` as ros::init / rospy.init_node do: ``from:=to`` is a remapping,
    ``_param:=value`` a private parameter (its value read as YAML, as rospy does), and the
    special ``__name:=``, ``__ns:=``, ``__log:=``, ... are taken out (roslaunch's own name and
    namespace win); the rest stay arguments. ``map_saver -f x map:=/robot1/map`` is the usual
    way to save a namespaced map."""
    rest: list[str] = []
    remaps: dict[str, str] = {}
    params: list[tuple[str, Any]] = []
    for tok in args:
        key, sep, value = tok.partition(":=")
        if not sep or not key or "=" in key or tok.startswith("-"):
            rest.append(tok)
        elif key.startswith("__"):
            continue
        elif key.startswith("_"):
            if len(key) < 2:  # roscpp skips it; here it would set the whole ~namespace
                raise LaunchError(f"{where}: args {tok!r}: the private parameter has no name")
            names.validate_name(key[1:], f" ({where}: args {tok!r})")
            try:
                params.append((key[1:], yaml.safe_load(value) if value else ""))
            except yaml.YAMLError as e:
                raise LaunchError(f"{where}: args {tok!r}: the value does not parse: {e}") from None
        else:
            src, dst = names.parse_remap(tok, f" ({where}: args)")
            remaps[src] = dst
    return rest, remaps, params
