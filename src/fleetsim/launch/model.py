"""What a launch file describes, once its args, groups and includes are resolved.

A `LaunchPlan` is flat, as roslaunch's is after loading: the parameter operations in file order
(all applied before any node starts) and the nodes in file order, each with its global
namespace, remaps and arguments. Frontends (XML, YAML) produce plans; the runner executes them.

Parameters are applied in roslaunch's phases, whatever their place in the file: first the
``<rosparam command="delete">`` and ``dump`` commands (roslaunch runs them as setup
executables, before any parameter is uploaded), then every ``clear_params`` namespace, then
every value in file order (the last one set wins).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from fleetsim.errors import LaunchError
from fleetsim.runtime.params import ParamTree

#: the phase of each kind of parameter operation (roslaunch's order, see the module docstring)
PHASES = {"delete": 0, "dump": 0, "clear": 1, "set": 2, "load": 2}


@dataclass
class ParamOp:
    """One parameter operation: ``set`` a value, ``load`` (merge) a mapping, ``delete`` a name
    (``<rosparam command="delete">``), ``clear`` a namespace (``clear_params``), or ``dump`` a
    namespace to the file ``value``.

    ``origins`` maps the keys of a loaded mapping (``a/b``, relative to ``name``; ``""`` for the
    value itself) to the ``file:line`` they came from, so a wrong value can be traced back.
    """

    kind: str
    name: str
    value: Any = None
    source: str = ""
    origins: dict[str, str] = field(default_factory=dict)

    def apply(self, tree: ParamTree) -> None:
        if self.kind == "set":
            tree.set(self.name, self.value, origin=self.origins.get("", self.source))
        elif self.kind == "load":
            tree.update(self.name, self.value, origins=self.origins)
        elif self.kind in ("delete", "clear"):
            if tree.has(self.name):
                tree.delete(self.name)
        elif self.kind == "dump":
            data = tree.get(self.name, {})
            try:
                Path(self.value).write_text(yaml.safe_dump(data, sort_keys=False))
            except OSError as e:
                raise LaunchError(f"{self.source}: cannot dump to {self.value}: {e}") from None
        else:  # pragma: no cover - frontends only make these kinds
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
    respawn_delay: float = 0.0
    required: bool = False
    #: roslaunch's ``cwd``: ROS_HOME (default) or node; nodes run in process, so the only
    #: thing it could change is where relative paths in args are read from (they are read
    #: from the current directory, as under ROS_HOME when roslaunch runs from there)
    cwd: str = "ROS_HOME"
    machine: str = ""
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
        # sorted() is stable: file order within each phase
        for op in sorted(self.params, key=lambda op: PHASES[op.kind]):
            op.apply(tree)

    def param_tree(self) -> ParamTree:
        tree = ParamTree()
        self.apply_params(tree)
        return tree

    def jitter_spawns(self, seed: int, jitter: float) -> None:
        """Move every ``gazebo_ros/spawn_model``'s ``-x``, ``-y`` (m) and ``-Y`` (rad) by a
        uniform draw within +-``jitter``, in node and argument order, from NumPy's
        ``default_rng(seed)``: the start noise of a seeded experiment (written to 4 decimals,
        as a launch file would carry them)."""
        rng = np.random.default_rng(seed)
        for spec in self.find_nodes("gazebo_ros", "spawn_model"):
            out, it = [], iter(spec.args)
            for a in it:
                out.append(a)
                if a in ("-x", "-y", "-Y"):
                    out.append(f"{float(next(it)) + rng.uniform(-jitter, jitter):.4f}")
            spec.args[:] = out

    def find_nodes(self, pkg: str | None = None, type: str | None = None) -> list[NodeSpec]:
        return [
            n
            for n in self.nodes
            if (pkg is None or n.pkg == pkg) and (type is None or n.type == type)
        ]
