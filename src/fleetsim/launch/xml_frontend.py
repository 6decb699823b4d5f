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
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from lxml import etree

from fleetsim.errors import FleetsimError, LaunchError, did_you_mean
from fleetsim.launch.model import LaunchPlan, NodeSpec, ParamOp
from fleetsim.launch.substitutions import Context, auto_value, substitute, to_bool
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


def convert_value(value: str, type_: str | None, where: str) -> Any:
    """roslaunch's value conversion: explicit ``type`` or int, then float, then bool, then str."""
    t = (type_ or "auto").strip().lower()
    try:
        if t in ("str", "string"):
            return value
        if t == "int":
            return int(value.strip())
        if t == "double":
            return float(value.strip())
        if t in ("bool", "boolean"):
            return to_bool(value, where)
        if t == "yaml":
            return yaml.safe_load(value)
    except (ValueError, yaml.YAMLError, LaunchError) as e:
        raise LaunchError(f"{where}: value {value!r} is not a valid {t}: {e}") from None
    if t != "auto":
        raise LaunchError(
            f"{where}: unknown param type {type_!r}; use str, int, double, bool or yaml"
        )
    return auto_value(value)


class XmlLoader:
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

    # -- parameters -------------------------------------------------------------------------
    def _param_name(self, name: str, scope: _Scope, where: str) -> str:
        if scope.node is not None:
            private = names.join(scope.ns, scope.node.name)
            if name.startswith("/"):
                return names.resolve(name, "/", where=f" ({where})")
            return names.resolve(name.lstrip("~"), private, where=f" ({where})")
        if name.startswith("~"):
            raise LaunchError(f"{where}: private parameter '{name}' outside a <node>")
        return names.resolve(name, scope.ns, where=f" ({where})")

    def _param(self, el, attrs, scope: _Scope) -> None:
        self._require(el, attrs, scope, "name")
        where = self._where(scope, el)
        sources = [k for k in ("value", "textfile", "binfile", "command") if k in attrs]
        if len(sources) != 1:
            raise LaunchError(
                f"{where}: <param name='{attrs['name']}'> needs exactly one of value, textfile, "
                f"binfile, command (got {sources or 'none'})"
            )
        kind = sources[0]
        if kind == "value":
            value = convert_value(attrs["value"], attrs.get("type"), where)
        elif kind in ("textfile", "binfile"):
            p = Path(attrs[kind])
            try:
                value = p.read_text() if kind == "textfile" else p.read_bytes()
            except OSError as e:
                raise LaunchError(f"{where}: cannot read {p}: {e.strerror}") from None
        else:
            value = self._command(attrs["command"], where)
            if attrs.get("type") and attrs["type"] not in ("str", "string"):
                value = convert_value(value, attrs["type"], where)
        name = self._param_name(attrs["name"], scope, where)
        self.plan.params.append(ParamOp("set", name, value, where))

    def _command(self, command: str, where: str) -> str:
        try:
            argv = shlex.split(command)
        except ValueError as e:
            raise LaunchError(f"{where}: command does not parse: {e}") from None
        if not argv:
            raise LaunchError(f"{where}: empty command")
        if Path(argv[0]).name in ("xacro", "xacro.py"):
            return self._xacro(argv[1:], where)
        try:
            out = subprocess.run(argv, capture_output=True, text=True, timeout=60, check=False)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise LaunchError(f"{where}: command {argv[0]!r} could not run: {e}") from None
        if out.returncode != 0:
            raise LaunchError(
                f"{where}: command {command!r} exited with {out.returncode}: "
                f"{out.stderr.strip()[:500]}"
            )
        return out.stdout

    def _xacro(self, argv: list[str], where: str) -> str:
        from fleetsim.description.urdf import urdf_text

        files, xargs = [], {}
        skip = False
        for a in argv:
            if skip:
                skip = False
                continue
            if a in ("-o", "--output"):
                skip = True
            elif a.startswith("-"):
                continue
            elif ":=" in a:
                k, _, v = a.partition(":=")
                xargs[k] = v
            else:
                files.append(a)
        if len(files) != 1:
            raise LaunchError(f"{where}: xacro needs exactly one input file, got {files}")
        try:
            text, _ = urdf_text(Path(files[0]), xargs)
        except FleetsimError as e:
            raise LaunchError(f"{where}: {e}") from None
        return text

    def _rosparam(self, el, attrs, scope: _Scope) -> None:
        where = self._where(scope, el)
        command = attrs.get("command", "load")
        base = names.join(scope.ns, scope.node.name) if scope.node is not None else scope.ns
        ns = self._ns_join(base, attrs.get("ns"), where)
        target = ns
        if attrs.get("param"):
            p = attrs["param"]
            target = (
                names.resolve(p, "/", where=f" ({where})")
                if p.startswith("/")
                else (names.join(ns, p))
            )
        if command == "delete":
            self.plan.params.append(ParamOp("delete", target, source=where))
            return
        if command == "dump":
            self.plan.notes.append(f"{where}: <rosparam command='dump'> skipped")
            return
        if command != "load":
            raise LaunchError(
                f"{where}: rosparam command must be load, dump or delete, got {command!r}"
            )
        if attrs.get("file"):
            path = Path(attrs["file"])
            try:
                text = path.read_text()
            except OSError as e:
                raise LaunchError(f"{where}: cannot read {path}: {e.strerror}") from None
            source = str(path)
        else:
            text = el.text or ""
            source = where
        if attrs.get("subst_value") and to_bool(attrs["subst_value"], where):
            text = substitute(text, scope.ctx, where) or ""
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            at = f":{mark.line + 1}" if mark is not None else ""
            problem = getattr(e, "problem", None) or str(e)
            raise LaunchError(f"{source}{at}: YAML does not parse: {problem} ({where})") from None
        if data is None:
            return
        if isinstance(data, dict) and not attrs.get("param"):
            self.plan.params.append(ParamOp("load", ns, data, where))
        elif attrs.get("param"):
            if isinstance(data, dict):
                self.plan.params.append(ParamOp("load", target, data, where))
            else:
                self.plan.params.append(ParamOp("set", target, data, where))
        else:
            raise LaunchError(
                f"{where}: rosparam content is a {type(data).__name__}, not a mapping; "
                "name it with param="
            )


def load_xml(path: str | Path, args: dict[str, str] | None = None, finder=None, seed: int = 0):
    """Read a roslaunch XML file (with its includes) into a `LaunchPlan`."""
    from fleetsim.launch.packages import default_finder

    path = Path(path).resolve()
    return XmlLoader(finder or default_finder(path), seed).load(path, dict(args or {}))
