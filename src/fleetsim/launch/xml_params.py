"""roslaunch XML's parameter elements: ``<param>`` (value, type, textfile, binfile, command)
and ``<rosparam>`` (load, delete; ``ns``, ``param``, ``subst_value``), as a mixin of the XML loader.

``command="$(find xacro)/xacro FILE name:=value"`` (and the older ``xacro.py``) runs the xacro
processor in process; other commands run as subprocesses, as roslaunch runs them.
"""

from __future__ import annotations

import shlex
import subprocess
from pathlib import Path
from typing import Any

import yaml

from fleetsim.errors import FleetsimError, LaunchError
from fleetsim.launch.model import ParamOp
from fleetsim.launch.substitutions import auto_value, substitute, to_bool
from fleetsim.runtime import names


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


class ParamElements:
    """The parameter elements; mixed into `XmlLoader` (which provides plan, _require, ...)."""

    def _param_name(self, name: str, scope: Any, where: str) -> str:
        if scope.node is not None:
            private = names.join(scope.ns, scope.node.name)
            if name.startswith("/"):
                return names.resolve(name, "/", where=f" ({where})")
            return names.resolve(name.lstrip("~"), private, where=f" ({where})")
        if name.startswith("~"):
            raise LaunchError(f"{where}: private parameter '{name}' outside a <node>")
        return names.resolve(name, scope.ns, where=f" ({where})")

    def _param(self, el, attrs, scope: Any) -> None:
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

    def _rosparam(self, el, attrs, scope: Any) -> None:
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
