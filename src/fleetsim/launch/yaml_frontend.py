"""Launch files in ROS 2's launch YAML schema, into the same `LaunchPlan` as the XML frontend.

Supported entries under ``launch:``: ``arg`` (name, default, description), ``let``,
``include`` (file, arg list), ``group`` (children, scoped), ``push-ros-namespace`` (also
``push_ros_namespace``), ``node`` (pkg, exec or type, name, namespace, args, param list with
``name``/``value`` or ``from`` file, remap list, output, respawn, if/unless), ``set_parameter``
and ``set_remap``. Substitutions are ROS 2's ``$(var)``, ``$(find-pkg-share)``, ``$(env)``,
``$(eval)`` and ROS 1's forms. Parameter files may be plain rosparam YAML or ROS 2's
``node: {ros__parameters: ...}`` layout. Errors name the file and the entry's path.
"""

from __future__ import annotations

import shlex
from pathlib import Path
from typing import Any

import yaml

from fleetsim.errors import FleetsimError, LaunchError, did_you_mean
from fleetsim.launch.model import LaunchPlan, NodeSpec, ParamOp
from fleetsim.launch.substitutions import Context, substitute, to_bool
from fleetsim.runtime import names
from fleetsim.runtime.param_yaml import load_yaml_lines

_KEYS = {
    "arg": {"name", "default", "description", "if", "unless"},
    "let": {"name", "value", "if", "unless"},
    "include": {"file", "arg", "if", "unless"},
    "group": {"children", "scoped", "forwarding", "if", "unless"},
    "push-ros-namespace": {"namespace"},
    "push_ros_namespace": {"namespace"},
    "node": {
        "pkg",
        "exec",
        "type",
        "name",
        "namespace",
        "args",
        "param",
        "remap",
        "output",
        "respawn",
        "required",
        "if",
        "unless",
        "ros_args",
        "launch-prefix",
        "env",
    },
    "set_parameter": {"name", "value", "if", "unless"},
    "set_remap": {"from", "to", "if", "unless"},
}


class YamlLoader:
    def __init__(self, finder, seed: int = 0) -> None:
        self.find = finder
        self.seed = seed
        self.plan = LaunchPlan()

    def load(self, path: Path, args: dict[str, str]) -> LaunchPlan:
        ctx = Context({}, self.find, path, seed=self.seed)
        self._file(Path(path), dict(args), "/", {}, ctx, top=True)
        return self.plan

    def _file(self, path, passed, ns, remaps, parent: Context, top=False) -> None:
        if not path.is_file():
            raise LaunchError(f"launch file {path} does not exist")
        try:
            data = yaml.safe_load(path.read_text())
        except yaml.YAMLError as e:
            mark = getattr(e, "problem_mark", None)
            at = f":{mark.line + 1}" if mark is not None else ""
            raise LaunchError(
                f"{path}{at}: YAML does not parse: {getattr(e, 'problem', e)}"
            ) from None
        if not isinstance(data, dict) or "launch" not in data:
            raise LaunchError(f"{path}: a YAML launch file holds a top-level 'launch:' list")
        if not isinstance(data["launch"], list):
            raise LaunchError(f"{path}: 'launch' must be a list of entries")
        self.plan.files.append(str(path))
        ctx = parent.child({}, path, dict(passed))
        self._entries(data["launch"], f"{path}: launch", ns, dict(remaps), ctx)
        unused = sorted(set(passed) - set(ctx.args))
        if unused:
            raise LaunchError(f"{path}: unused args {unused}; declared: {sorted(ctx.args)}")
        if top:
            self.plan.args = {k: v for k, v in ctx.args.items() if v is not None}

    def _s(self, value: Any, ctx: Context, where: str) -> Any:
        if isinstance(value, str):
            return substitute(value, ctx, where)
        if isinstance(value, list):
            return [self._s(v, ctx, where) for v in value]
        if isinstance(value, dict):
            return {k: self._s(v, ctx, where) for k, v in value.items()}
        return value

    def _entries(self, entries, where, ns, remaps, ctx) -> str:
        for i, entry in enumerate(entries):
            w = f"{where}[{i}]"
            if not isinstance(entry, dict) or len(entry) != 1:
                raise LaunchError(f"{w}: each entry is a one-key mapping like 'node: {{...}}'")
            ((kind, body),) = entry.items()
            if kind not in _KEYS:
                raise LaunchError(f"{w}: unknown entry '{kind}'{did_you_mean(kind, _KEYS)}")
            w = f"{w}.{kind}"
            body = body or {}
            if not isinstance(body, dict):
                raise LaunchError(f"{w}: expected a mapping")
            for key in body:
                if key not in _KEYS[kind]:
                    raise LaunchError(f"{w}: unknown key '{key}'{did_you_mean(key, _KEYS[kind])}")
            if kind != "arg" and not self._enabled(body, ctx, w):
                continue
            ns = getattr(self, "_" + kind.replace("-", "_"))(body, w, ns, remaps, ctx) or ns
        return ns

    def _enabled(self, body, ctx, w) -> bool:
        if "if" in body and not to_bool(str(self._s(body["if"], ctx, w + ".if")), w):
            return False
        return not ("unless" in body and to_bool(str(self._s(body["unless"], ctx, w)), w))

    def _arg(self, body, w, ns, remaps, ctx) -> None:
        if "name" not in body:
            raise LaunchError(f"{w}: missing 'name'")
        name = body["name"]
        if name in ctx.args:
            raise LaunchError(f"{w}: arg '{name}' is declared twice")
        default = body.get("default")
        ctx.args[name] = ctx.passed.get(
            name, None if default is None else str(self._s(default, ctx, w))
        )

    def _let(self, body, w, ns, remaps, ctx) -> None:
        ctx.args[body["name"]] = str(self._s(body.get("value", ""), ctx, w))

    def _push_ros_namespace(self, body, w, ns, remaps, ctx) -> str:
        sub = str(self._s(body.get("namespace", ""), ctx, w))
        if sub.startswith("/"):
            return names.validate_namespace(sub, f" ({w})")
        return names.validate_namespace(names.join(ns, sub.strip("/")), f" ({w})")

    def _group(self, body, w, ns, remaps, ctx) -> None:
        children = body.get("children") or []
        if not isinstance(children, list):
            raise LaunchError(f"{w}.children: expected a list")
        scoped = to_bool(str(body.get("scoped", "true")), w)
        inner_remaps = dict(remaps) if scoped else remaps
        self._entries(children, f"{w}.children", ns, inner_remaps, ctx)

    def _include(self, body, w, ns, remaps, ctx) -> None:
        path = Path(str(self._s(body.get("file", ""), ctx, w)))
        if not path.is_absolute():
            path = Path(ctx.filename).parent / path
        passed = {}
        for j, a in enumerate(body.get("arg") or []):
            if not isinstance(a, dict) or "name" not in a or "value" not in a:
                raise LaunchError(f"{w}.arg[{j}]: needs name and value")
            passed[a["name"]] = str(self._s(a["value"], ctx, w))
        if path.suffix in (".launch", ".xml"):
            from fleetsim.launch.xml_frontend import XmlLoader, _Scope

            xml = XmlLoader(self.find, self.seed)
            xml.plan = self.plan
            xml._file(path, passed, _Scope(ns, dict(remaps), ctx, path))
        else:
            self._file(path, passed, ns, remaps, ctx)

    def _set_parameter(self, body, w, ns, remaps, ctx) -> None:
        name = names.resolve(str(body["name"]), ns, where=f" ({w})")
        self.plan.params.append(ParamOp("set", name, self._s(body.get("value"), ctx, w), w))

    def _set_remap(self, body, w, ns, remaps, ctx) -> None:
        remaps[str(self._s(body["from"], ctx, w))] = str(self._s(body["to"], ctx, w))

    def _node(self, body, w, ns, remaps, ctx) -> None:
        body = self._s(body, ctx, w)
        exe = body.get("exec") or body.get("type")
        for key, val in (("pkg", body.get("pkg")), ("exec", exe), ("name", body.get("name"))):
            if not val:
                raise LaunchError(f"{w}: missing '{key}'")
        node_ns = ns
        if body.get("namespace"):
            sub = str(body["namespace"])
            node_ns = (
                names.validate_namespace(sub, f" ({w})")
                if sub.startswith("/")
                else names.validate_namespace(names.join(ns, sub.strip("/")), f" ({w})")
            )
        names.validate_base_name(str(body["name"]), f" ({w})")
        args = body.get("args") or ""
        node = NodeSpec(
            pkg=str(body["pkg"]),
            type=str(exe),
            name=str(body["name"]),
            namespace=node_ns,
            args=shlex.split(args) if isinstance(args, str) else [str(a) for a in args],
            remaps=dict(remaps),
            output=str(body.get("output", "log")),
            respawn=to_bool(str(body.get("respawn", "false")), w),
            required=to_bool(str(body.get("required", "false")), w),
            source=w,
        )
        for j, r in enumerate(body.get("remap") or []):
            if not isinstance(r, dict) or "from" not in r or "to" not in r:
                raise LaunchError(f"{w}.remap[{j}]: needs from and to")
            node.remaps[str(r["from"])] = str(r["to"])
        private = names.join(node_ns, node.name)
        for j, p in enumerate(body.get("param") or []):
            self._node_param(p, f"{w}.param[{j}]", private, node.name)
        self.plan.nodes.append(node)

    def _node_param(self, p, w, private: str, node_name: str) -> None:
        if not isinstance(p, dict):
            raise LaunchError(f"{w}: expected {{name, value}} or {{from: FILE}}")
        if "from" in p:
            path = Path(str(p["from"]))
            try:
                raw, lines = load_yaml_lines(path.read_text(), str(path))
            except OSError as e:
                raise LaunchError(f"{w}: cannot read {path}: {e.strerror}") from None
            except FleetsimError as e:
                raise LaunchError(f"{w}: {e}") from None
            data = ros2_params(raw, node_name)
            if data:
                origins = lines if data is raw else _section_origins(raw, node_name, lines)
                self.plan.params.append(ParamOp("load", private, data, w, origins))
            return
        if "name" not in p or "value" not in p:
            raise LaunchError(f"{w}: needs name and value (or from)")
        name = str(p["name"]).replace(".", "/")  # ROS 2 dotted names are namespaces here
        full = names.resolve(name, "/") if name.startswith("/") else names.join(private, name)
        self.plan.params.append(ParamOp("set", full, p["value"], w))


def _section_origins(data: dict, node_name: str, lines: dict[str, str]) -> dict[str, str]:
    """The lines of the keys `ros2_params` takes, relative to the node's namespace."""
    out: dict[str, str] = {}
    for key in ("**", node_name):
        for k in data:
            k = str(k).strip("/")
            if k == key or k.endswith("/" + key):
                prefix = f"{k}/ros__parameters/"
                out.update({p[len(prefix) :]: o for p, o in lines.items() if p.startswith(prefix)})
    return out


def ros2_params(data: Any, node_name: str) -> dict:
    """Parameters for ``node_name`` from a ROS 2 file (``/**`` and the node's own section), or
    the mapping itself for a plain rosparam file."""
    if not isinstance(data, dict):
        return {}
    sections = {
        k.lstrip("/"): v for k, v in data.items() if isinstance(v, dict) and "ros__parameters" in v
    }
    if not sections:
        return data
    out: dict = {}
    for key in ("**", node_name):
        for k, v in sections.items():
            if k == key or k.endswith("/" + key):
                out.update(v["ros__parameters"])
    return out


def load_yaml(path: str | Path, args: dict[str, str] | None = None, finder=None, seed: int = 0):
    """Read a ROS 2 style YAML launch file into a `LaunchPlan`."""
    from fleetsim.launch.packages import default_finder

    path = Path(path).resolve()
    return YamlLoader(finder or default_finder(path), seed).load(path, dict(args or {}))
