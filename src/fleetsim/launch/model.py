"""What a launch file describes, once its args, groups and includes are resolved.

A `LaunchPlan` is flat, as roslaunch's is after loading: the parameter operations in file order
(all applied before any node starts) and the nodes in file order, each with its global
namespace, remaps and arguments. Frontends (XML, YAML) produce plans; the runner executes them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from fleetsim.runtime.params import ParamTree


@dataclass
class ParamOp:
    """One parameter operation: ``set`` a value, ``load`` (merge) a mapping, or ``delete``."""

    kind: str
    name: str
    value: Any = None
    source: str = ""

    def apply(self, tree: ParamTree) -> None:
        if self.kind == "set":
            tree.set(self.name, self.value)
        elif self.kind == "load":
            tree.update(self.name, self.value)
        elif self.kind == "delete":
            if tree.has(self.name):
                tree.delete(self.name)
        else:  # pragma: no cover - frontends only make the three kinds
            raise ValueError(self.kind)


@dataclass
class NodeSpec:
    """A ``<node>``: which class to run, under which name, namespace, remaps and args."""

    pkg: str
    type: str
    name: str
    namespace: str = "/"
    args: list[str] = field(default_factory=list)
    remaps: dict[str, str] = field(default_factory=dict)
    output: str = "log"
    respawn: bool = False
    required: bool = False
    env: dict[str, str] = field(default_factory=dict)
    source: str = ""

    @property
    def full_name(self) -> str:
        return (self.namespace.rstrip("/") or "") + "/" + self.name


@dataclass
class LaunchPlan:
    """Everything a launch file asked for, in order."""

    params: list[ParamOp] = field(default_factory=list)
    nodes: list[NodeSpec] = field(default_factory=list)
    args: dict[str, str] = field(default_factory=dict)
    files: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def apply_params(self, tree: ParamTree) -> None:
        for op in self.params:
            op.apply(tree)

    def param_tree(self) -> ParamTree:
        tree = ParamTree()
        self.apply_params(tree)
        return tree

    def find_nodes(self, pkg: str | None = None, type: str | None = None) -> list[NodeSpec]:
        return [
            n
            for n in self.nodes
            if (pkg is None or n.pkg == pkg) and (type is None or n.type == type)
        ]
