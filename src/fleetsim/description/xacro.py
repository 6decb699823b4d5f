"""xacro → URDF text without ROS, through ``xacrodoc`` (which vendors the ROS xacro processor).

``$(find pkg)`` is answered from a :class:`~fleetsim.description.packages.PackageIndex`;
``$(arg name)`` from the ``args`` mapping (``name:=value`` on a command line). Relative
``<xacro:include filename=...>`` paths resolve against the including file, as in ROS.
"""

from __future__ import annotations

import contextlib
import io
import threading
import xml.parsers.expat
from collections.abc import Iterable, Mapping
from pathlib import Path

import xacro as _xacro
import xacrodoc  # noqa: F401  (imported for its side effect of configuring xacro)
from xacro import substitution_args as _subst
from xacrodoc import xacrodoc as _xacrodoc

from fleetsim.description.packages import PackageIndex
from fleetsim.errors import DescriptionError

_LOCK = threading.Lock()  # xacro keeps module-level state (file stack, includes, arg context)


def is_xacro(path: Path, text: str | None = None) -> bool:
    """True for ``*.xacro`` files or text that declares the xacro namespace."""
    if Path(path).suffix == ".xacro":
        return True
    return text is not None and "http://www.ros.org/wiki/xacro" in text


def parse_cli_args(items: Iterable[str]) -> dict[str, str]:
    """``["name:=value", ...]`` → ``{"name": "value"}``, as roslaunch and xacro read them."""
    out: dict[str, str] = {}
    for item in items:
        name, sep, value = item.partition(":=")
        if not sep or not name.strip():
            raise DescriptionError(
                f"argument '{item}' is not of the form name:=value (e.g. use_arm:=true)"
            )
        out[name.strip()] = value
    return out


def expand_xacro(
    path: Path,
    args: Mapping[str, str] | None = None,
    index: PackageIndex | None = None,
) -> tuple[str, list[Path]]:
    """Expand the xacro file ``path``; return the URDF text and every file read (top first).

    Raises :class:`DescriptionError` naming the file (and the include chain) on any xacro error:
    a missing argument, an unknown package, an include that does not exist, bad XML.
    """
    path = Path(path).resolve()
    if not path.is_file():
        raise DescriptionError(f"{path}: no such file")
    if index is None:
        index = PackageIndex(near=path)
    text = path.read_text()
    with _LOCK:
        saved_find = _subst._eval_find
        saved_dict_find = _subst._eval_dict.get("find")
        _subst._eval_find = index.get_path
        _subst._eval_dict["find"] = index.get_path
        _xacro.all_includes = []
        _xacro.init_stacks(str(path))
        stderr = io.StringIO()
        try:
            with contextlib.redirect_stderr(stderr):
                dom = _xacrodoc._compile_xacro_file(text, subargs=dict(args or {}))
            includes = [Path(p).resolve() for p in _xacro.all_includes]
            urdf = dom.toxml()
        except DescriptionError as exc:
            raise DescriptionError(f"{_where(path)}: {exc}") from None
        except (_subst.ArgException, _xacro.XacroException) as exc:
            arg_exc = exc if isinstance(exc, _subst.ArgException) else exc.exc
            if not isinstance(arg_exc, _subst.ArgException):
                raise DescriptionError(f"{_where(path)}: xacro error: {exc}") from None
            name = arg_exc.args[0]
            raise DescriptionError(
                f"{_where(path)}: xacro argument '{name}' is not set and has no default; "
                f"pass {name}:=VALUE"
            ) from None
        except xml.parsers.expat.ExpatError as exc:
            raise DescriptionError(f"{_where(path)}: XML syntax error: {exc}") from None
        except Exception as exc:  # xacro raises XacroException, NameError, ValueError ...
            where = _where(path)
            detail = stderr.getvalue().strip().replace("\n", "; ")
            raise DescriptionError(
                f"{where}: xacro error: {exc}" + (f" ({detail})" if detail else "")
            ) from None
        finally:
            _subst._eval_find = saved_find
            if saved_dict_find is not None:
                _subst._eval_dict["find"] = saved_dict_find
            _xacro.init_stacks(None)
    files = [path, *[p for p in dict.fromkeys(includes) if p != path]]
    return urdf, files


def _where(top: Path) -> str:
    """The file being processed when xacro failed, with the include chain back to ``top``."""
    stack = [f for f in (_xacro.filestack or []) if f]
    if not stack or (len(stack) == 1 and Path(stack[0]).resolve() == top):
        return str(top)
    chain = " included from ".join(str(f) for f in reversed(stack))
    return chain
