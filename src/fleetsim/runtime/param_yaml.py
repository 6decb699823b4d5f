"""Parameter YAML as rosparam reads it, with the file and line of every key.

rosparam loads YAML with PyYAML's safe loader plus its own angle tags: ``!radians EXPR`` and
``rad(EXPR)`` (an expression in ``pi``), ``!degrees N`` and ``deg(N)`` (degrees to radians), so a
file with ``yaw: deg(90)`` loads as 1.5708 here too. `load_yaml_lines` also returns where each
key was written (``{"a/b": "file.yaml:7"}``), which is how a parameter of the wrong type is
reported with the line it came from.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import yaml

from fleetsim.errors import ParameterError


class RosparamLoader(yaml.SafeLoader):
    """PyYAML's safe loader with rosparam's ``!radians`` / ``!degrees`` tags and their
    implicit ``rad(...)`` / ``deg(...)`` forms (rosparam registers the same on SafeLoader)."""


def _radians(loader: RosparamLoader, node: yaml.Node) -> float:
    value = loader.construct_scalar(node).strip()  # type: ignore[arg-type]
    expr = value[4:-1] if value.startswith("rad(") else value
    try:
        # rosparam evaluates the expression with pi in scope; nothing else is reachable here
        return float(eval(expr, {"__builtins__": {}}, {"pi": math.pi}))
    except Exception:
        raise yaml.constructor.ConstructorError(
            None, None, f"invalid radian expression: {value}", node.start_mark
        ) from None


def _degrees(loader: RosparamLoader, node: yaml.Node) -> float:
    value = loader.construct_scalar(node).strip()  # type: ignore[arg-type]
    expr = value[4:-1] if value.startswith("deg(") else value
    try:
        return float(expr) * math.pi / 180.0
    except ValueError:
        raise yaml.constructor.ConstructorError(
            None, None, f"invalid degree value: {value}", node.start_mark
        ) from None


RosparamLoader.add_constructor("!radians", _radians)
RosparamLoader.add_constructor("!degrees", _degrees)
RosparamLoader.add_implicit_resolver("!degrees", re.compile(r"^deg\([^\)]*\)$"), ["d"])
RosparamLoader.add_implicit_resolver("!radians", re.compile(r"^rad\([^\)]*\)$"), ["r"])


def _yaml_error(e: yaml.YAMLError, source: str, line_offset: int) -> ParameterError:
    mark = getattr(e, "problem_mark", None)
    at = f":{mark.line + 1 + line_offset}:{mark.column + 1}" if mark is not None else ""
    problem = getattr(e, "problem", None) or str(e).splitlines()[0]
    return ParameterError(f"{source}{at}: YAML does not parse: {problem}")


def load_yaml_lines(
    text: str, source: str = "<string>", line_offset: int = 0
) -> tuple[Any, dict[str, str]]:
    """Parse parameter YAML; return the data and ``{key path: "source:line"}``.

    Parameters
    ----------
    text : the YAML text.
    source : the file name (or launch file element) the text came from, for messages.
    line_offset : the line of ``source`` on which ``text`` starts, minus one (0 for a file).

    The key path of a nested key is its keys joined by ``/`` (``local_costmap/inflation``);
    ``""`` names the document itself.
    """
    loader = RosparamLoader(text)
    try:
        node = loader.get_single_node()
        data = loader.construct_document(node) if node is not None else None
        origins: dict[str, str] = {}
        if node is not None:
            origins[""] = f"{source}:{node.start_mark.line + 1 + line_offset}"
            _key_lines(loader, node, "", source, line_offset, origins)
    except yaml.YAMLError as e:
        raise _yaml_error(e, source, line_offset) from None
    finally:
        loader.dispose()
    return data, origins


def _key_lines(
    loader: RosparamLoader,
    node: yaml.Node,
    prefix: str,
    source: str,
    offset: int,
    out: dict[str, str],
) -> None:
    if not isinstance(node, yaml.MappingNode):
        return
    # construct_document has already flattened merge keys (<<) into node.value
    for key_node, value_node in node.value:
        if not isinstance(key_node, yaml.ScalarNode):
            continue
        key = str(loader.construct_object(key_node)).strip("/")
        path = f"{prefix}{key}"
        out[path] = f"{source}:{key_node.start_mark.line + 1 + offset}"
        _key_lines(loader, value_node, path + "/", source, offset, out)


def load_yaml_text(text: str, source: str = "<string>") -> Any:
    """Parse parameter YAML (rosparam's tags included); errors name the source and line."""
    return load_yaml_lines(text, source)[0]


def read_yaml_file(path: str | Path) -> str:
    path = Path(path)
    try:
        return path.read_text()
    except OSError as e:
        raise ParameterError(f"cannot read parameter file {path}: {e.strerror}") from None


def load_yaml_file(path: str | Path) -> Any:
    """Read a YAML parameter file; errors name the file and line."""
    return load_yaml_text(read_yaml_file(path), str(path))
