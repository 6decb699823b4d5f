"""roslaunch XML: ``<launch>`` files as ROS 1 users write them, into a `LaunchPlan`.

Every tag and attribute of roslaunch's XML specification (``xmlloader.py`` of ros_comm) reads
as roslaunch reads it, or is an error that names the file, the line and what fleetsim does not
support. The rules that matter most:

- ``if``/``unless`` are evaluated first; a tag they switch off is skipped whole, so its other
  attributes (a ``$(find)`` of a package that is not installed) are never evaluated.
- ``<arg>``: ``value`` is fixed (setting it from outside is an error), ``default`` can be
  overridden, neither declares an arg that must be passed. Args declared inside a ``<group>``
  are not seen after it. ``<include pass_all_args="true">`` passes every arg in scope; the
  included file may re-declare them, and passed args it does not declare are ignored (ROS
  Melodic and later); without it, a passed arg the file does not declare is an error.
- Booleans: ``if``/``unless`` take true/false/1/0; ``respawn``, ``required``,
  ``clear_params``, ``pass_all_args`` and ``subst_value`` take only true/false, as roslaunch.
- ``clear_params`` clears before any parameter is set; ``<rosparam command="delete">`` runs
  before both (see `fleetsim.launch.model`). ``<group clear_params>`` needs ``ns``.
- ``~name`` params outside a ``<node>`` go to every later node in the same scope.
- Relative ``<include file>`` paths are read from the current directory, as roslaunch does.
- ``<test>`` is checked and skipped (roslaunch does not run tests; rostest does).
- Not supported, and an error: ``launch-prefix`` (nodes run in this process) and nodes on a
  ``<machine>`` whose address is not this host (use ``fleetsim launch --connect`` there).

Substitution args are those of `fleetsim.launch.substitutions`, ROS 1's set only.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from fleetsim.errors import LaunchError, did_you_mean
from fleetsim.launch.model import LaunchPlan, ParamOp
from fleetsim.launch.substitutions import ROS1_KINDS, Context, strict_bool, substitute, to_bool
from fleetsim.launch.xml_nodes import NodeElements
from fleetsim.launch.xml_params import ParamElements
from fleetsim.runtime import names

_NODE_ATTRS = {"pkg", "type", "name", "args", "ns", "output", "respawn", "respawn_delay",
               "required", "machine", "launch-prefix", "cwd", "clear_params"}  # fmt: skip
# fmt: off
_ATTRS = {
    "launch": {"deprecated"},
    "arg": {"name", "default", "value", "doc"},
    "param": {"name", "value", "type", "textfile", "binfile", "command"},
    "rosparam": {"command", "file", "param", "ns", "subst_value"},
    "group": {"ns", "clear_params"},
    "include": {"file", "ns", "clear_params", "pass_all_args"},
    "node": _NODE_ATTRS,
    "remap": {"from", "to"},
    "env": {"name", "value"},
    "master": {"auto"},
    "machine": {"name", "address", "env-loader", "ssh-port", "user", "password", "default",
                "timeout", "ros-root", "ros-package-path", "ros-ip", "ros-hostname"},
    "test": (_NODE_ATTRS - {"respawn", "respawn_delay", "output"})
    | {"test-name", "time-limit", "retry"},
}
# fmt: on
_IN_LAUNCH = {
    "arg",
    "param",
    "rosparam",
    "group",
    "include",
    "node",
    "remap",
    "env",
    "master",
    "machine",
    "test",
}  # fmt: skip
_IN_NODE = {"remap", "param", "rosparam", "env"}
_IN_INCLUDE = {"arg", "env"}


@dataclass
class _Scope:
    ns: str
    remaps: dict[str, str]
    ctx: Context
    file: Path
    node: Any = None
    env: dict[str, str] = field(default_factory=dict)
    #: ``~name`` params set outside a node: (name, value, where), applied to later nodes
    private: list[tuple[str, Any, str]] = field(default_factory=list)
    #: inside a <node>: its <param> operations, set after its <rosparam>s as roslaunch does
    pending: list[ParamOp] | None = None
    #: the <include> elements this file was reached through, innermost first ("" at the top):
    #: a node's errors at start-up name them (the same file included twice is two places)
    included_from: str = ""

    def child(self, **kw: Any) -> _Scope:
        base = {
            "ns": self.ns,
            "remaps": dict(self.remaps),
            "ctx": self.ctx,
            "file": self.file,
            "node": self.node,
            "env": dict(self.env),
            "private": self.private,
            "pending": self.pending,
            "included_from": self.included_from,
        }
        base.update(kw)
        return _Scope(**base)


class XmlLoader(ParamElements, NodeElements):
    """Loads one top-level launch file (and everything it includes) into a plan."""

    def __init__(self, finder, seed: int = 0) -> None:
        self.find = finder
        self.seed = seed
        self.plan = LaunchPlan()
        #: declared machines: name -> address; and the current default machine
        self.machines: dict[str, str] = {}
        self.default_machine = ""
        #: ``_param:=value`` of nodes' args: set after every parameter of the launch, as the
        #: node sets them itself when it starts (ros::init), after roslaunch set the rest
        self.arg_params: list = []

    # -- entry ----------------------------------------------------------------------------
    def load(self, path: Path, args: dict[str, str]) -> LaunchPlan:
        ctx = Context({}, self.find, path, seed=self.seed, kinds=ROS1_KINDS)
        scope = _Scope("/", {}, ctx, Path(path))
        self._file(Path(path), dict(args), scope, top=True)
        self.plan.params.extend(self.arg_params)
        return self.plan

    def _where(self, scope: _Scope, el, attr: str | None = None) -> str:
        tag = el.tag if isinstance(el.tag, str) else "?"
        a = f" attribute '{attr}'" if attr else ""
        return f"{scope.file}:{el.sourceline} <{tag}>{a}"

    def _file(
        self,
        path: Path,
        passed: dict[str, str],
        scope: _Scope,
        top: bool = False,
        pass_all_args: bool = False,
    ) -> None:
        path = Path(path)
        if not path.is_file():
            raise LaunchError(f"launch file {path} does not exist{self._near_files(path)}")
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
        ctx = dataclasses.replace(
            scope.ctx.child({}, path, dict(passed), pass_all_args), kinds=ROS1_KINDS
        )
        fscope = scope.child(ctx=ctx, file=path)
        attrs = self._attrs(root, fscope)
        if attrs and attrs.get("deprecated"):
            self.plan.notes.append(f"{path}: DEPRECATED: {attrs['deprecated']}")
        self._children(root, fscope, _IN_LAUNCH)
        unused = sorted(set(passed) - set(ctx.args))
        # roslaunch checks for unused args only without pass_all_args; fleetsim also checks the
        # command line (roslaunch ignores a mistyped name:=value there)
        if unused and not pass_all_args:
            what = "on the command line" if top else f"to the include of {path}"
            hint = "".join(did_you_mean(u, ctx.args) for u in unused)
            raise LaunchError(
                f"{path}: unused args {unused} passed {what}; the file declares "
                f"{sorted(ctx.args) or 'no args'}{hint}"
            )
        if top:
            self.plan.args = {k: v for k, v in ctx.args.items() if v is not None}

    @staticmethod
    def _near_files(path: Path) -> str:
        from fleetsim.launch.packages import similar_files

        return similar_files(path)

    # -- elements -------------------------------------------------------------------------
    def _children(self, el, scope: _Scope, allowed: set[str]) -> None:
        for child in el:
            if not isinstance(child.tag, str):
                continue
            self._element(child, scope, allowed)

    def _attrs(self, el, scope: _Scope) -> dict[str, str] | None:
        """Substituted attributes, or None when if/unless says skip.

        As roslaunch, ``if``/``unless`` are evaluated first and a skipped tag's other
        attributes are never substituted. ``type`` of ``<param>`` is read as written (roslaunch
        does not substitute it)."""
        known = _ATTRS[el.tag] | {"if", "unless"}
        for key in el.attrib:
            if key not in known:
                raise LaunchError(
                    f"{self._where(scope, el, key)}: unknown attribute{did_you_mean(key, known)}"
                )
        if "if" in el.attrib and "unless" in el.attrib:
            raise LaunchError(f"{self._where(scope, el)}: both 'if' and 'unless' are set")
        for key, keep in (("if", True), ("unless", False)):
            if key in el.attrib:
                where = self._where(scope, el, key)
                if to_bool(substitute(el.attrib[key], scope.ctx, where) or "", where) != keep:
                    return None
        out: dict[str, str] = {}
        for key, raw in el.attrib.items():
            if key in ("if", "unless"):
                continue
            if key == "type" and el.tag == "param":
                out[key] = raw
                continue
            out[key] = substitute(raw, scope.ctx, self._where(scope, el, key))
        return out

    def _element(self, el, scope: _Scope, allowed: set[str]) -> None:
        tag = el.tag
        if tag not in _ATTRS or tag == "launch":
            raise LaunchError(
                f"{self._where(scope, el)}: unknown element <{tag}>{did_you_mean(tag, allowed)}"
            )
        if tag not in allowed:
            raise LaunchError(f"{self._where(scope, el)}: <{tag}> is not allowed here")
        attrs = self._attrs(el, scope)
        if attrs is None:
            return
        getattr(self, "_" + tag)(el, attrs, scope)

    def _require(self, el, attrs, scope, *keys: str) -> None:
        for k in keys:
            if not attrs.get(k):
                raise LaunchError(f"{self._where(scope, el)}: missing required attribute '{k}'")

    def _flag(self, el, attrs, scope, key: str) -> bool:
        """A true/false attribute as roslaunch's ``_bool_attr`` reads it (absent: false)."""
        if key not in attrs:
            return False
        return strict_bool(attrs[key], self._where(scope, el, key))

    def _arg(self, el, attrs, scope: _Scope) -> None:
        # roslaunch's LoaderContext.add_arg
        self._require(el, attrs, scope, "name")
        name = attrs["name"]
        ctx = scope.ctx
        where = self._where(scope, el)
        if name in ctx.args and not ctx.pass_all_args:
            raise LaunchError(f"{where}: arg '{name}' is declared twice")
        current = ctx.value_of(name)
        if "value" in attrs:
            if "default" in attrs:
                raise LaunchError(f"{where}: arg '{name}' has both value and default")
            if current is not None and not ctx.pass_all_args:
                raise LaunchError(
                    f"{where}: arg '{name}' has a fixed value and cannot be set from outside; "
                    "declare it with default= instead"
                )
            ctx.args[name] = attrs["value"]
        elif "default" in attrs:
            ctx.args[name] = current if current is not None else attrs["default"]
        else:
            ctx.args[name] = current
        self._check_choices(el, scope, name, ctx.args[name])

    def _check_choices(self, el, scope: _Scope, name: str, value: str | None) -> None:
        """ROS 2's ``<arg name="x"><choice value="a"/>...</arg>`` (DeclareLaunchArgument's
        choices), read in ROS 1 files too (roslaunch ignores an arg's children): a value
        outside the choices is an error naming the arg and the allowed values."""
        choices = []
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if child.tag != "choice" or set(child.attrib) != {"value"}:
                raise LaunchError(
                    f'{self._where(scope, child)}: <arg> may hold only <choice value="..."/>'
                )
            choices.append(child.attrib["value"])
        if choices and value is not None and value not in choices:
            raise LaunchError(
                f"{self._where(scope, el)}: arg '{name}' is '{value}'; allowed values: "
                + ", ".join(choices)
            )

    def _master(self, el, attrs, scope) -> None:
        self.plan.notes.append(f"{self._where(scope, el)}: ignoring defunct <master/> tag")

    def _env(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "name")
        if "value" not in attrs:
            raise LaunchError(f"{self._where(scope, el)}: missing required attribute 'value'")
        target = scope.node.env if scope.node is not None else scope.env
        target[attrs["name"]] = attrs["value"]

    def _remap(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "from", "to")
        where = self._where(scope, el)
        names.validate_name(attrs["from"], f" ({where})")
        names.validate_name(attrs["to"], f" ({where})")
        target = scope.node.remaps if scope.node is not None else scope.remaps
        target[attrs["from"]] = attrs["to"]

    def _ns_join(self, base: str, ns: str | None, where: str) -> str:
        if ns is None:
            return base
        if not ns:
            raise LaunchError(f"{where}: the 'ns' attribute is empty")
        if ns.startswith("/"):
            return names.validate_namespace(ns, f" ({where})")
        names.validate_namespace(ns, f" ({where})")
        return names.validate_namespace(names.join(base, ns.strip("/")), f" ({where})")

    def _clear(self, el, attrs, scope: _Scope, ns: str) -> None:
        if self._flag(el, attrs, scope, "clear_params"):
            if "ns" not in attrs:
                raise LaunchError(
                    f"{self._where(scope, el)}: 'ns' attribute must be set in order to use "
                    "'clear_params'"
                )
            self.plan.params.append(ParamOp("clear", ns, source=self._where(scope, el)))

    def _group(self, el, attrs, scope: _Scope) -> None:
        ns = self._ns_join(scope.ns, attrs.get("ns"), self._where(scope, el, "ns"))
        self._clear(el, attrs, scope, ns)
        inner = scope.child(ns=ns, ctx=scope.ctx.scoped(), private=list(scope.private))
        self._children(el, inner, _IN_LAUNCH)

    def _include(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "file")
        where = self._where(scope, el)
        path = self._include_path(attrs["file"], scope, where)
        ns = self._ns_join(scope.ns, attrs.get("ns"), self._where(scope, el, "ns"))
        self._clear(el, attrs, scope, ns)
        pass_all = self._flag(el, attrs, scope, "pass_all_args")
        passed: dict[str, str] = {}
        if pass_all:
            # roslaunch passes its whole arg dictionary: declared args and those passed in
            ctx = scope.ctx
            for k in [*ctx.passed, *ctx.args]:
                if ctx.value_of(k) is not None:
                    passed[k] = ctx.value_of(k)
        chain = f"{where}, included from {scope.included_from}" if scope.included_from else where
        inner = scope.child(ns=ns, included_from=chain)
        declared: set[str] = set()
        for child in el:
            if not isinstance(child.tag, str):
                continue
            if child.tag not in _IN_INCLUDE:
                raise LaunchError(
                    f"{self._where(scope, child)}: <{child.tag}> is not allowed inside <include>"
                    " (only <arg> and <env>)"
                )
            a = self._attrs(child, scope)
            if a is None:
                continue
            if child.tag == "env":
                self._env(child, a, inner)
                continue
            self._include_arg(child, a, scope, passed, declared, pass_all)
        try:
            self._file(path, passed, inner, pass_all_args=pass_all)
        except LaunchError as e:
            if str(path) in str(e) and where in str(e):
                raise
            raise LaunchError(f"{e} (included from {where})") from None

    def _include_arg(self, el, a, scope, passed: dict, declared: set, pass_all: bool) -> None:
        self._require(el, a, scope, "name")
        name, w = a["name"], self._where(scope, el)
        if name in declared and not pass_all:
            raise LaunchError(f"{w}: arg '{name}' is passed twice to this <include>")
        declared.add(name)
        if "value" in a and "default" in a:
            raise LaunchError(f"{w}: arg '{name}' has both value and default")
        if "value" in a:
            passed[name] = a["value"]
        elif "default" in a:
            passed.setdefault(name, a["default"])
        elif name not in passed:
            raise LaunchError(f"{w}: <arg name='{name}'> in an <include> needs value=")

    def _include_path(self, file: str, scope: _Scope, where: str) -> Path:
        path = Path(file)
        if path.is_absolute() or path.is_file():
            return path.resolve() if path.is_file() else path
        beside = scope.file.parent / path
        if beside.is_file():
            raise LaunchError(
                f"{where}: launch file {file} does not exist in the current directory; "
                f"roslaunch reads relative include paths from there. Write "
                f'file="$(dirname)/{file}" for the one next to this file'
            )
        return path


def load_xml(path: str | Path, args: dict[str, str] | None = None, finder=None, seed: int = 0):
    """Read a roslaunch XML file (with its includes) into a `LaunchPlan`."""
    from fleetsim.launch.packages import default_finder

    path = Path(path).resolve()
    return XmlLoader(finder or default_finder(path), seed).load(path, dict(args or {}))
