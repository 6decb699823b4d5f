"""roslaunch XML: ``<launch>`` files as ROS 1 users write them, into a `LaunchPlan`.

Supported: ``<arg>``, ``<param>`` (value, type, textfile, binfile, command — xacro commands run
in process), ``<rosparam>`` (load from a file or inline YAML, delete; ``ns``, ``param``,
``subst_value``), ``<group ns clear_params>``, ``<include file ns pass_all_args>`` with nested
``<arg>``, ``<node>`` with ``<remap>``, ``<param>``, ``<rosparam>``, ``<env>`` inside,
launch-level ``<remap>`` and ``<env>``, ``<master>`` and ``<machine>`` (accepted), ``if`` and
``unless`` on every element, and the substitution args of `fleetsim.launch.substitutions`.
Every error names the file, the line and the element.
"""

from __future__ import annotations

import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from fleetsim.errors import LaunchError, did_you_mean
from fleetsim.launch.model import LaunchPlan, NodeSpec, ParamOp
from fleetsim.launch.substitutions import Context, substitute, to_bool
from fleetsim.launch.xml_params import ParamElements
from fleetsim.runtime import names

_ATTRS = {
    "launch": {"deprecated"},
    "arg": {"name", "default", "value", "doc"},
    "param": {"name", "value", "type", "textfile", "binfile", "command"},
    "rosparam": {"command", "file", "param", "ns", "subst_value"},
    "group": {"ns", "clear_params"},
    "include": {"file", "ns", "clear_params", "pass_all_args"},
    "node": {
        "pkg",
        "type",
        "name",
        "args",
        "ns",
        "output",
        "respawn",
        "respawn_delay",
        "required",
        "machine",
        "launch-prefix",
        "cwd",
        "clear_params",
    },
    "remap": {"from", "to"},
    "env": {"name", "value"},
    "master": {"auto"},
    "machine": {"name", "address", "env-loader", "default", "user", "password", "timeout"},
    "test": {"pkg", "type", "name", "test-name", "args", "ns", "time-limit", "retry"},
}
_IN_LAUNCH = {"arg", "param", "rosparam", "group", "include", "node", "remap", "env", "master",
              "machine", "test"}  # fmt: skip
_IN_NODE = {"remap", "param", "rosparam", "env"}
_IN_INCLUDE = {"arg", "env"}


@dataclass
class _Scope:
    ns: str
    remaps: dict[str, str]
    ctx: Context
    file: Path
    node: NodeSpec | None = None
    env: dict[str, str] = field(default_factory=dict)

    def child(self, **kw: Any) -> _Scope:
        base = {
            "ns": self.ns,
            "remaps": dict(self.remaps),
            "ctx": self.ctx,
            "file": self.file,
            "node": self.node,
            "env": dict(self.env),
        }
        base.update(kw)
        return _Scope(**base)


class XmlLoader(ParamElements):
    """Loads one top-level launch file (and everything it includes) into a plan."""

    def __init__(self, finder, seed: int = 0) -> None:
        self.find = finder
        self.seed = seed
        self.plan = LaunchPlan()

    # -- entry ----------------------------------------------------------------------------
    def load(self, path: Path, args: dict[str, str]) -> LaunchPlan:
        ctx = Context({}, self.find, path, seed=self.seed)
        scope = _Scope("/", {}, ctx, Path(path))
        self._file(Path(path), dict(args), scope, top=True)
        return self.plan

    def _where(self, scope: _Scope, el, attr: str | None = None) -> str:
        tag = el.tag if isinstance(el.tag, str) else "?"
        a = f" attribute '{attr}'" if attr else ""
        return f"{scope.file}:{el.sourceline} <{tag}>{a}"

    def _file(self, path: Path, passed: dict[str, str], scope: _Scope, top: bool = False) -> None:
        path = Path(path)
        if not path.is_file():
            raise LaunchError(f"launch file {path} does not exist")
        try:
            tree = etree.parse(str(path), etree.XMLParser(remove_comments=True))
        except etree.XMLSyntaxError as e:
            raise LaunchError(f"{path}:{e.lineno}: XML does not parse: {e.msg}") from None
        root = tree.getroot()
        if root.tag != "launch":
            raise LaunchError(
                f"{path}:{root.sourceline}: the root element must be <launch>, not <{root.tag}>"
            )
        self.plan.files.append(str(path))
        ctx = scope.ctx.child({}, path, dict(passed))
        fscope = scope.child(ctx=ctx, file=path)
        self._children(root, fscope, _IN_LAUNCH)
        unused = sorted(set(passed) - set(ctx.args))
        if unused:
            what = "on the command line" if top else f"to the include of {path}"
            raise LaunchError(
                f"{path}: unused args {unused} passed {what}; the file declares "
                f"{sorted(ctx.args) or 'no args'}"
            )
        if top:
            self.plan.args = {k: v for k, v in ctx.args.items() if v is not None}

    # -- elements -------------------------------------------------------------------------
    def _children(self, el, scope: _Scope, allowed: set[str]) -> None:
        for child in el:
            if not isinstance(child.tag, str):
                continue
            self._element(child, scope, allowed)

    def _attrs(self, el, scope: _Scope) -> dict[str, str] | None:
        """Substituted attributes, or None when if/unless says skip."""
        known = _ATTRS[el.tag] | {"if", "unless"}
        out: dict[str, str] = {}
        for key, raw in el.attrib.items():
            if key not in known:
                raise LaunchError(
                    f"{self._where(scope, el, key)}: unknown attribute{did_you_mean(key, known)}"
                )
            out[key] = substitute(raw, scope.ctx, self._where(scope, el, key))
        if "if" in out and "unless" in out:
            raise LaunchError(f"{self._where(scope, el)}: both 'if' and 'unless' are set")
        if "if" in out and not to_bool(out["if"], self._where(scope, el, "if")):
            return None
        if "unless" in out and to_bool(out["unless"], self._where(scope, el, "unless")):
            return None
        return out

    def _element(self, el, scope: _Scope, allowed: set[str]) -> None:
        tag = el.tag
        if tag not in _ATTRS:
            raise LaunchError(
                f"{self._where(scope, el)}: unknown element <{tag}>{did_you_mean(tag, allowed)}"
            )
        if tag not in allowed:
            raise LaunchError(f"{self._where(scope, el)}: <{tag}> is not allowed here")
        # <arg> declarations are processed before their if/unless can refer to themselves.
        attrs = self._attrs(el, scope)
        if attrs is None:
            return
        getattr(self, "_" + tag)(el, attrs, scope)

    def _require(self, el, attrs, scope, *keys: str) -> None:
        for k in keys:
            if not attrs.get(k):
                raise LaunchError(f"{self._where(scope, el)}: missing required attribute '{k}'")

    def _arg(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "name")
        name = attrs["name"]
        ctx = scope.ctx
        if name in ctx.args:
            raise LaunchError(f"{self._where(scope, el)}: arg '{name}' is declared twice")
        passed = ctx.passed
        if "value" in attrs:
            if "default" in attrs:
                raise LaunchError(
                    f"{self._where(scope, el)}: arg '{name}' has both value and default"
                )
            if name in passed:
                raise LaunchError(
                    f"{self._where(scope, el)}: arg '{name}' has a fixed value and cannot be "
                    "set from outside; declare it with default= instead"
                )
            ctx.args[name] = attrs["value"]
        else:
            ctx.args[name] = passed.get(name, attrs.get("default"))

    def _master(self, el, attrs, scope) -> None:
        return

    def _machine(self, el, attrs, scope) -> None:
        self.plan.notes.append(
            f"{self._where(scope, el)}: <machine> accepted; every node runs here (use "
            "`fleetsim node run` to place nodes on other machines)"
        )

    def _test(self, el, attrs, scope) -> None:
        self.plan.notes.append(f"{self._where(scope, el)}: <test> skipped (rostest is not run)")

    def _env(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "name")
        target = scope.node.env if scope.node is not None else scope.env
        target[attrs["name"]] = attrs.get("value", "")

    def _remap(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "from", "to")
        where = self._where(scope, el)
        names.validate_name(attrs["from"], f" ({where})")
        names.validate_name(attrs["to"], f" ({where})")
        target = scope.node.remaps if scope.node is not None else scope.remaps
        target[attrs["from"]] = attrs["to"]

    def _ns_join(self, base: str, ns: str | None, where: str) -> str:
        if not ns:
            return base
        if ns.startswith("/"):
            return names.validate_namespace(ns, f" ({where})")
        names.validate_namespace(ns, f" ({where})")
        return names.validate_namespace(names.join(base, ns.strip("/")), f" ({where})")

    def _group(self, el, attrs, scope: _Scope) -> None:
        ns = self._ns_join(scope.ns, attrs.get("ns"), self._where(scope, el, "ns"))
        if attrs.get("clear_params") and to_bool(attrs["clear_params"], self._where(scope, el)):
            self.plan.params.append(ParamOp("delete", ns, source=self._where(scope, el)))
        self._children(el, scope.child(ns=ns), _IN_LAUNCH)

    def _include(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "file")
        where = self._where(scope, el)
        path = Path(attrs["file"])
        if not path.is_absolute():
            path = scope.file.parent / path
        ns = self._ns_join(scope.ns, attrs.get("ns"), where)
        passed: dict[str, str] = {}
        if attrs.get("pass_all_args") and to_bool(attrs["pass_all_args"], where):
            passed.update({k: v for k, v in scope.ctx.args.items() if v is not None})
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if child.tag not in _IN_INCLUDE:
                raise LaunchError(
                    f"{self._where(scope, child)}: <{child.tag}> is not allowed inside <include>"
                )
            a = self._attrs(child, scope)
            if a is None:
                continue
            if child.tag == "env":
                scope.env[a.get("name", "")] = a.get("value", "")
                continue
            self._require(child, a, scope, "name")
            if "value" not in a and "default" not in a:
                raise LaunchError(
                    f"{self._where(scope, child)}: <arg name='{a['name']}'> in an <include> "
                    "needs value="
                )
            passed[a["name"]] = a.get("value", a.get("default"))
        try:
            self._file(path, passed, scope.child(ns=ns))
        except LaunchError as e:
            if str(path) in str(e) and where in str(e):
                raise
            raise LaunchError(f"{e} (included from {where})") from None

    def _node(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "pkg", "type", "name")
        where = self._where(scope, el)
        names.validate_base_name(attrs["name"], f" ({where})")
        ns = self._ns_join(scope.ns, attrs.get("ns"), where)
        try:
            args = shlex.split(attrs.get("args", ""))
        except ValueError as e:
            raise LaunchError(f"{where}: args do not parse: {e}") from None
        node = NodeSpec(
            pkg=attrs["pkg"],
            type=attrs["type"],
            name=attrs["name"],
            namespace=ns,
            args=args,
            remaps=dict(scope.remaps),
            output=attrs.get("output", "log"),
            respawn=to_bool(attrs.get("respawn", "false"), where),
            required=to_bool(attrs.get("required", "false"), where),
            env=dict(scope.env),
            source=where,
        )
        private = names.join(ns, node.name)
        if attrs.get("clear_params") and to_bool(attrs["clear_params"], where):
            self.plan.params.append(ParamOp("delete", private, source=where))
        self._children(el, scope.child(node=node, ns=ns), _IN_NODE)
        self.plan.nodes.append(node)


def load_xml(path: str | Path, args: dict[str, str] | None = None, finder=None, seed: int = 0):
    """Read a roslaunch XML file (with its includes) into a `LaunchPlan`."""
    from fleetsim.launch.packages import default_finder

    path = Path(path).resolve()
    return XmlLoader(finder or default_finder(path), seed).load(path, dict(args or {}))
