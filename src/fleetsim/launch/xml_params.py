"""roslaunch XML's parameter elements: ``<param>`` (value, type, textfile, binfile, command)
and ``<rosparam>`` (load, dump, delete; ``ns``, ``param``, ``subst_value``), as a mixin of the
XML loader, with roslaunch's rules (``xmlloader.py`` and ``loader.py`` of ros_comm):

- ``value`` is stripped and, like ``textfile`` and ``command`` output, converted by ``type``
  (``auto`` when absent: float if it has a '.', else int, else true/false, else text).
- Inside a ``<node>`` every ``<param>`` name is the node's private name (a leading ``/`` too,
  as roslaunch's name joining does); ``<rosparam param="/x">`` stays global.
- ``~name`` outside a node is kept for every later ``<node>`` in the scope.
- ``<rosparam>``'s ``ns`` and ``param`` are joined; content that is not a mapping needs one.
- rosparam's ``!degrees``/``deg()`` and ``!radians``/``rad()`` load as radians.

Every value remembers its file and line (a rosparam file's own line, or the launch file's), so a
value of the wrong type is reported where it was written.

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
from fleetsim.runtime.param_yaml import load_yaml_lines


def convert_value(value: str, type_: str | None, where: str) -> Any:
    """roslaunch's value conversion: explicit ``type`` or ``auto`` (see `auto_value`)."""
    t = (type_ or "auto").strip().lower()
    try:
        if t in ("str", "string"):
            return value
        if t == "int":
            return int(value)
        if t == "double":
            return float(value)
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


def _ns_join(ns: str, name: str) -> str:
    """rosgraph's ``ns_join``: a global or private name stays as it is."""
    if not name or name.startswith(("/", "~")) or not ns:
        return name or ns
    return ns.rstrip("/") + "/" + name


def _text_line(path: Path, el) -> int:
    """The line on which an element's text starts: the end of its start tag."""
    try:
        lines = Path(path).read_text().splitlines()
    except OSError:
        return el.sourceline
    i = el.sourceline - 1
    col = lines[i].find("<" + el.tag) if i < len(lines) else -1
    if col < 0:
        return el.sourceline
    quote = ""
    while i < len(lines):
        for ch in lines[i][col:]:
            if quote:
                quote = "" if ch == quote else quote
            elif ch in "\"'":
                quote = ch
            elif ch == ">":
                return i + 1
        i, col = i + 1, 0
    return el.sourceline


class ParamElements:
    """The parameter elements; mixed into `XmlLoader` (which provides plan, _require, ...)."""

    def _param_name(self, name: str, scope: Any, where: str) -> str:
        if scope.node is not None:
            # roslaunch joins every node <param> name onto the node's private namespace
            private = names.join(scope.ns, scope.node.name)
            return names.resolve(name.lstrip("~/"), private, where=f" ({where})")
        return names.resolve(name, scope.ns, where=f" ({where})")

    def _read(self, kind: str, path: str, where: str, binary: bool = False):
        from fleetsim.launch.packages import similar_files

        p = Path(path)
        try:
            return p.read_bytes() if binary else p.read_text()
        except OSError as e:
            raise LaunchError(
                f"{where}: cannot read {kind} {p}: {e.strerror}{similar_files(p)}"
            ) from None

    def _param(self, el, attrs, scope: Any) -> None:
        self._require(el, attrs, scope, "name")
        where = self._where(scope, el)
        sources = [k for k in ("value", "textfile", "binfile", "command") if k in attrs]
        if len(sources) != 1:
            raise LaunchError(
                f"{where}: <param name='{attrs['name']}'> needs exactly one of value, textfile, "
                f"binfile, command (got {sources or 'none'})"
            )
        kind, ptype = sources[0], attrs.get("type")
        if kind == "value":
            value = convert_value(attrs["value"].strip(), ptype, where)
        elif kind == "textfile":
            value = convert_value(self._read("textfile", attrs[kind], where), ptype, where)
        elif kind == "binfile":
            value = self._read("binfile", attrs[kind], where, binary=True)
        else:
            value = convert_value(self._command(attrs["command"], where), ptype, where)
        name = attrs["name"].strip()
        if scope.node is None and name.startswith("~"):
            scope.private.append((name, value, where))
            return
        op = ParamOp("set", self._param_name(name, scope, where), value, where)
        if scope.pending is not None:
            scope.pending.append(op)
        else:
            self.plan.params.append(op)

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
        from fleetsim.launch.packages import similar_files

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
        if not Path(files[0]).is_file():
            raise LaunchError(
                f"{where}: xacro input {files[0]} does not exist{similar_files(Path(files[0]))}"
            )
        try:
            text, _ = urdf_text(Path(files[0]), xargs)
        except FleetsimError as e:
            raise LaunchError(f"{where}: {e}") from None
        return text

    def _rosparam(self, el, attrs, scope: Any) -> None:
        where = self._where(scope, el)
        command = attrs.get("command") or "load"
        if command not in ("load", "dump", "delete"):
            raise LaunchError(
                f"{where}: rosparam command must be load, dump or delete, got {command!r}"
            )
        base = names.join(scope.ns, scope.node.name) if scope.node is not None else scope.ns
        param = _ns_join(attrs.get("ns") or "", attrs.get("param") or "")
        if param.startswith("~"):
            raise LaunchError(
                f"{where}: a private rosparam name ({param!r}) outside a <node> is not "
                "supported; put the <rosparam> inside the node"
            )
        full = names.resolve(param, base, where=f" ({where})") if param else base
        file = attrs.get("file")
        if command == "delete":
            if file is not None:
                raise LaunchError(f"{where}: 'file' attribute is invalid with 'delete' command")
            self.plan.params.append(ParamOp("delete", full, source=where))
            return
        if command == "dump":
            if not file:
                raise LaunchError(f"{where}: <rosparam command='dump'> needs file=")
            self.plan.params.append(ParamOp("dump", full, file, source=where))
            return
        if file is not None:
            text = self._read("rosparam file", file, where)
            source, offset = str(Path(file)), 0
        else:
            text = (el.text or "") + "".join(c.tail or "" for c in el)
            source, offset = str(scope.file), _text_line(scope.file, el) - 1
        if self._flag(el, attrs, scope, "subst_value"):
            text = substitute(text, scope.ctx, where) or ""
        try:
            data, origins = load_yaml_lines(text, source, offset)
        except FleetsimError as e:
            raise LaunchError(f"{e} ({where})") from None
        if data is None:
            return
        if not param and not isinstance(data, dict):
            raise LaunchError(
                f"{where}: rosparam content is a {type(data).__name__}, not a mapping; "
                "name it with param="
            )
        kind = "load" if isinstance(data, dict) else "set"
        self.plan.params.append(ParamOp(kind, full, data, where, origins))
