"""The parameter server: a nested dict addressed by global names, with rosparam's semantics
(loading a YAML mapping into a namespace merges leaf by leaf; setting a dict replaces).

It remembers where each value was set (``file.yaml:7``, ``robot.launch:12 <param>``); a namespace
read from it is a `ParamDict` carrying those origins, which `fleetsim.runtime.params.load_params`
puts in its messages.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from fleetsim.errors import ParameterError
from fleetsim.runtime import names
from fleetsim.runtime.param_yaml import load_yaml_lines, read_yaml_file

_MISSING = object()


class ParamDict(dict):
    """A namespace read from a `ParamTree`: a plain dict plus ``origins``, which maps each of its
    keys to where the value was set (``"amcl.yaml:7"``). Nested namespaces are ParamDicts too."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.origins: dict[str, str] = {}

    @classmethod
    def copy_of(cls, values: Mapping[str, Any] | None) -> ParamDict:
        """A shallow copy of ``values`` that keeps the origins it carries (a plain ``dict()``
        copy drops them, and a bad value's error then no longer names its file and line)."""
        out = cls(values or {})
        out.origins.update(getattr(values, "origins", None) or {})
        return out


# YAML writes a ParamDict as the mapping it is (recordings and `param dump` serialise trees)
yaml.SafeDumper.add_representer(ParamDict, yaml.SafeDumper.represent_dict)
yaml.representer.SafeRepresenter.add_multi_representer(
    ParamDict, yaml.representer.SafeRepresenter.represent_dict
)
yaml.Dumper.add_representer(ParamDict, yaml.Dumper.represent_dict)


class ParamTree:
    """The rosparam-style parameter server: a nested dict addressed by global names."""

    def __init__(self) -> None:
        self._root: dict[str, Any] = {}
        #: global name -> where it was set; a namespace's origin covers what is under it
        self._origins: dict[str, str] = {}

    def origin(self, name: str) -> str | None:
        """Where ``name`` (or the nearest namespace above it that was set whole) was set."""
        keys = self._keys(name)
        for i in range(len(keys), 0, -1):
            found = self._origins.get("/" + "/".join(keys[:i]))
            if found:
                return found
        return None

    def _forget(self, keys: list[str]) -> None:
        """Drop the origins at ``keys`` and under it (cheap unless it holds a namespace)."""
        if not self._origins:
            return
        if not keys:
            self._origins.clear()
            return
        full = "/" + "/".join(keys)
        self._origins.pop(full, None)
        node: Any = self._root
        for k in keys:
            node = node.get(k) if isinstance(node, dict) else None
        if isinstance(node, dict) and node:
            for k in [k for k in self._origins if k.startswith(full + "/")]:
                del self._origins[k]

    def _sourced(self, prefix: str, node: dict, inherited: str | None) -> ParamDict:
        """A ParamDict copy of ``node`` (at ``prefix``) with each key's origin; ``inherited`` is
        the origin of the nearest namespace above that was set whole."""
        out = ParamDict()
        for k, v in node.items():
            child = f"{prefix}/{k}"
            origin = self._origins.get(child, inherited) if self._origins else None
            out[k] = self._sourced(child, v, origin) if isinstance(v, dict) else copy.deepcopy(v)
            if origin:
                out.origins[str(k)] = origin
        return out

    @staticmethod
    def _keys(name: str) -> list[str]:
        names.validate_name(name)
        if not name.startswith("/"):
            raise ParameterError(f"parameter name '{name}' must be resolved (global) here")
        return [k for k in name.split("/") if k]

    def has(self, name: str) -> bool:
        node: Any = self._root
        for k in self._keys(name):
            if not isinstance(node, dict) or k not in node:
                return False
            node = node[k]
        return True

    def get(self, name: str, default: Any = _MISSING) -> Any:
        """The value at a global name (a deep copy for namespaces)."""
        node: Any = self._root
        for k in self._keys(name):
            if not isinstance(node, dict) or k not in node:
                if default is _MISSING:
                    raise ParameterError(f"parameter '{name}' is not set")
                return default
            node = node[k]
        if isinstance(node, dict):
            keys = self._keys(name)
            prefix = "/" + "/".join(keys) if keys else ""
            return self._sourced(prefix, node, self.origin(name) if keys else None)
        return copy.deepcopy(node) if isinstance(node, list) else node

    def set(self, name: str, value: Any, origin: str | None = None) -> None:
        """Set a value; a dict replaces the whole namespace (rosparam ``set``). ``origin`` says
        where the value came from (``file.yaml:3``), for messages about it."""
        keys = self._keys(name)
        self._forget(keys)
        if origin:
            self._origins["/" + "/".join(keys)] = origin
        if not keys:
            if not isinstance(value, dict):
                raise ParameterError("the root namespace '/' can only be set to a dict")
            self._root = copy.deepcopy(dict(value))
            return
        node = self._root
        for i, k in enumerate(keys[:-1]):
            nxt = node.get(k)
            if not isinstance(nxt, dict):
                nxt = node[k] = {}
                self._origins.pop("/" + "/".join(keys[: i + 1]), None)
            node = nxt
        node[keys[-1]] = copy.deepcopy(value)

    def update(
        self, namespace: str, values: Mapping[str, Any], origins: Mapping[str, str] | None = None
    ) -> None:
        """Merge a mapping into a namespace leaf by leaf (rosparam ``load``). ``origins`` maps
        key paths relative to ``namespace`` (``a/b``) to where they were written."""
        self._update(namespace, values, origins or {}, "")

    def _update(
        self, namespace: str, values: Mapping[str, Any], origins: Mapping[str, str], rel: str
    ) -> None:
        ns = names.validate_namespace(namespace)
        for key, value in values.items():
            key = str(key)
            full = names.join(ns, key.lstrip("/")) if not key.startswith("/") else key
            path = rel + key.strip("/")
            if isinstance(value, Mapping) and value:
                self._update(full, value, origins, path + "/")
            else:
                self.set(full, value, origins.get(path))

    def delete(self, name: str) -> None:
        keys = self._keys(name)
        node: Any = self._root
        for k in keys[:-1]:
            node = node.get(k) if isinstance(node, dict) else None
            if node is None:
                raise ParameterError(f"cannot delete parameter '{name}': not set")
        if not isinstance(node, dict) or keys[-1] not in node:
            raise ParameterError(f"cannot delete parameter '{name}': not set")
        del node[keys[-1]]
        self._forget(keys)

    def search(self, key: str, namespace: str) -> str | None:
        """ROS ``searchParam``: the closest ``key`` found walking up from ``namespace``."""
        ns = names.validate_namespace(namespace)
        while True:
            candidate = names.join(ns, key)
            if self.has(candidate):
                return candidate
            if ns == "/":
                return None
            ns = names.namespace_of(ns)

    def names(self) -> list[str]:
        """Every leaf parameter's global name, sorted."""
        out: list[str] = []

        def walk(prefix: str, node: Any) -> None:
            if isinstance(node, dict) and node:
                for k, v in node.items():
                    walk(f"{prefix}/{k}", v)
            else:
                out.append(prefix or "/")

        walk("", self._root)
        return sorted(out)

    def load_file(self, path: str | Path, namespace: str = "/") -> None:
        """``rosparam load FILE NS``: merge a YAML file's mapping into ``namespace``."""
        data, origins = load_yaml_lines(read_yaml_file(path), str(path))
        if data is None:
            return
        if not isinstance(data, Mapping):
            raise ParameterError(
                f"{path}: a parameter file must hold a mapping at the top level, "
                f"got {type(data).__name__}"
            )
        self.update(namespace, data, origins)
