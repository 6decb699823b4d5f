"""What a batch runs: the cross product of scenarios, launch arguments and seeds.

A spec comes from a YAML file (`load_spec`) or the command line's short form (`spec_from_cli`)::

    scenarios: [barn]            # shipped scenario names or launch files (relative to this file)
    args:                        # every scenario must declare each of these <arg>s
      world: 3..15               # a range of integers, ends included
      speed: [0.2, 0.4]          # a list; "0.2,0.4" and "0.1..0.5:0.1" (a float range) too
      barn_dir: /data/barn       # one value
    seeds: 0..9                  # a range, a list, or one integer
    duration: 100                # sim s each run lasts at most
    until_goals: true            # end a run early once every robot's goals are done
    timeout: 600                 # wall s after which a run is killed and recorded as failed
    metrics: barn                # scenario metrics (default: the one registered for its name)

Everything is checked before any run starts: an unknown scenario, an argument a launch file
does not declare, an empty sweep or a malformed range is a `BatchError` naming it, and every
distinct argument combination is loaded once (so a missing file shows up now, not in run 37).
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from lxml import etree

from fleetsim.errors import BatchError, FleetsimError, did_you_mean

SPEC_KEYS = ("scenarios", "args", "seeds", "duration", "until_goals", "timeout", "metrics")
DEFAULT_DURATION = 60.0  # s of sim time
DEFAULT_TIMEOUT = 600.0  # s of wall time
_INT_RANGE = re.compile(r"^\s*(-?\d+)\s*\.\.\s*(-?\d+)\s*$")
_FLOAT_RANGE = re.compile(r"^\s*([-+.\deE]+)\s*\.\.\s*([-+.\deE]+)\s*:\s*([-+.\deE]+)\s*$")


@dataclass(frozen=True)
class RunSpec:
    """One run: a scenario (shipped name or launch file path), its arguments and seed."""

    index: int
    scenario: str
    args: tuple[tuple[str, str], ...]
    seed: int
    duration: float
    until_goals: bool
    metrics: str | None

    @property
    def run_id(self) -> str:
        """A stable name for the run (what it runs, not where it is in the sweep), so that
        ``--resume`` recognises it after the spec gained or lost values."""
        key = json.dumps(
            [self.scenario, list(self.args), self.seed, self.duration, self.until_goals]
        )
        return hashlib.sha1(key.encode()).hexdigest()[:12]

    def to_json(self) -> dict[str, Any]:
        return {
            "index": self.index,
            "scenario": self.scenario,
            "args": dict(self.args),
            "seed": self.seed,
            "duration": self.duration,
            "until_goals": self.until_goals,
            "metrics": self.metrics,
        }

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> RunSpec:
        return cls(
            d["index"],
            d["scenario"],
            tuple(sorted(d["args"].items())),
            int(d["seed"]),
            float(d["duration"]),
            bool(d["until_goals"]),
            d["metrics"],
        )


@dataclass
class BatchSpec:
    """A sweep: scenario names (as the user gave them), argument values, seeds."""

    scenarios: list[str]
    args: dict[str, list[str]] = field(default_factory=dict)
    seeds: list[int] = field(default_factory=lambda: [0])
    duration: float = DEFAULT_DURATION
    until_goals: bool = True
    timeout: float = DEFAULT_TIMEOUT
    metrics: str | None = None
    #: the folder user files are relative to; shipped to a cluster as the runs' working dir
    workdir: Path = field(default_factory=Path.cwd)
    source: str = "the command line"

    def runs(self) -> list[RunSpec]:
        names = sorted(self.args)
        combos = list(itertools.product(*(self.args[n] for n in names)))
        out = []
        for scenario, combo, seed in itertools.product(self.scenarios, combos, self.seeds):
            out.append(
                RunSpec(
                    len(out),
                    scenario,
                    tuple(zip(names, combo)),
                    seed,
                    self.duration,
                    self.until_goals,
                    self.metrics,
                )
            )
        return out


# -- values ---------------------------------------------------------------------------------
def parse_values(name: str, value: Any, where: str) -> list[str]:
    """The values of one swept argument: a list, ``"a,b,c"``, ``"A..B"`` (integers, ends
    included), ``"A..B:STEP"`` (floats), or a single value. A value with a ``/`` is a path
    (``../data``), never a range."""
    if isinstance(value, list):
        out = [_scalar(name, v, where) for v in value]
    elif isinstance(value, str) and ".." in value and not any(c in value for c in "/\\"):
        out = _range(name, value, where)
    elif isinstance(value, str) and "," in value:
        out = [v.strip() for v in value.split(",")]
        if any(v == "" for v in out):
            raise BatchError(f"{where}: arg '{name}': empty value in '{value}'")
    else:
        out = [_scalar(name, value, where)]
    if not out:
        raise BatchError(f"{where}: arg '{name}' sweeps no values (an empty sweep)")
    if len(set(out)) != len(out):
        raise BatchError(f"{where}: arg '{name}' repeats a value: {out}")
    return out


def _scalar(name: str, v: Any, where: str) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float, str)):
        return str(v)
    raise BatchError(f"{where}: arg '{name}': value {v!r} is not a number or a string")


def _range(name: str, text: str, where: str) -> list[str]:
    m = _INT_RANGE.match(text)
    if m:
        a, b = int(m[1]), int(m[2])
        if b < a:
            raise BatchError(f"{where}: arg '{name}': range '{text}' is empty (end below start)")
        return [str(i) for i in range(a, b + 1)]
    m = _FLOAT_RANGE.match(text)
    if m:
        try:
            a, b, step = float(m[1]), float(m[2]), float(m[3])
        except ValueError:
            m = None
        else:
            if step <= 0 or b < a:
                raise BatchError(
                    f"{where}: arg '{name}': range '{text}' is empty (needs start <= end and "
                    "a positive step)"
                )
            count = math.floor((b - a) / step + 1e-9) + 1  # the end if a step lands on it
            # printed as the shortest decimals that round-trip, so 0.1..0.3:0.1 gives 0.3
            return [repr(round(a + i * step, 10)) for i in range(count)]
    raise BatchError(
        f"{where}: arg '{name}': malformed range '{text}'; write A..B (integers, ends "
        "included) or A..B:STEP (numbers)"
    )


def parse_seeds(value: Any, where: str) -> list[int]:
    """Seeds: ``"0..9"``, a list of integers, or one integer."""
    values = parse_values("seeds", value, where)
    try:
        seeds = [int(v) for v in values]
    except ValueError:
        raise BatchError(f"{where}: seeds must be integers, got {values}") from None
    if any(s < 0 for s in seeds):
        raise BatchError(f"{where}: seeds must be >= 0, got {seeds}")
    return seeds


# -- scenarios ------------------------------------------------------------------------------
def resolve_scenario(name: str, workdir: Path) -> Path:
    """The launch file of a scenario: a file (relative to ``workdir``) or a shipped name."""
    from fleetsim.launch.scenarios import scenarios

    p = Path(name) if Path(name).is_absolute() else workdir / name
    if p.is_file():
        return p
    known = scenarios()
    if name in known:
        return known[name]
    raise BatchError(
        f"unknown scenario '{name}': neither a launch file in {workdir} nor a shipped scenario"
        f"{did_you_mean(name, known)}; shipped: {', '.join(known)}"
    )


def declared_args(path: Path) -> set[str]:
    """The arguments a launch file takes from outside: its top-level ``<arg>``s without a
    fixed ``value`` (XML), or its top-level ``arg`` entries (YAML)."""
    if path.suffix in (".yaml", ".yml"):
        try:
            data = yaml.safe_load(path.read_text())
        except yaml.YAMLError as e:
            raise BatchError(f"{path}: YAML does not parse: {e}") from None
        entries = data.get("launch", []) if isinstance(data, dict) else []
        return {
            str(e["arg"]["name"])
            for e in entries
            if isinstance(e, dict) and isinstance(e.get("arg"), dict) and "name" in e["arg"]
        }
    try:
        root = etree.parse(str(path)).getroot()
    except etree.XMLSyntaxError as e:
        raise BatchError(f"{path}: XML does not parse: {e}") from None
    return {el.get("name") for el in root.findall("arg") if el.get("value") is None}


def validate(spec: BatchSpec) -> list[RunSpec]:
    """Check every scenario, argument and combination; the runs, or a `BatchError`."""
    from fleetsim.launch.runner import load_plan

    if not spec.scenarios:
        raise BatchError(f"{spec.source}: no scenario to run (an empty sweep)")
    if not spec.seeds:
        raise BatchError(f"{spec.source}: no seeds (an empty sweep)")
    if spec.duration <= 0:
        raise BatchError(f"{spec.source}: duration must be > 0 s, got {spec.duration}")
    if spec.timeout <= 0:
        raise BatchError(f"{spec.source}: timeout must be > 0 s, got {spec.timeout}")
    from fleetsim.batch.metrics import metrics_class, metrics_name_for

    names = sorted(spec.args)
    for scenario in spec.scenarios:
        path = resolve_scenario(scenario, spec.workdir)
        metrics_name = metrics_name_for(scenario, spec.metrics)
        metrics = metrics_class(metrics_name) if metrics_name is not None else None
        declared = declared_args(path)
        for name in names:
            if name not in declared:
                raise BatchError(
                    f"{spec.source}: scenario '{scenario}' ({path}) declares no arg '{name}'"
                    f"{did_you_mean(name, declared)}; it declares "
                    f"{', '.join(sorted(declared)) or 'none'}"
                )
        for combo in itertools.product(*(spec.args[n] for n in names)):
            args = dict(zip(names, combo))
            try:
                # relative paths in a launch file are read from the working directory, as the
                # runs will read them
                with contextlib.chdir(spec.workdir):
                    load_plan(path, args, seed=spec.seeds[0])
                    if metrics is not None:
                        metrics.check(args)
            except FleetsimError as e:
                raise BatchError(f"{spec.source}: scenario '{scenario}' with {args}: {e}") from e
    return spec.runs()


# -- sources --------------------------------------------------------------------------------
def load_spec(path: str | Path) -> BatchSpec:
    """Read a spec file (see the module docstring); not yet validated."""
    path = Path(path)
    if not path.is_file():
        raise BatchError(f"batch spec {path} does not exist")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as e:
        raise BatchError(f"{path}: YAML does not parse: {e}") from None
    if not isinstance(data, dict):
        raise BatchError(f"{path}: a batch spec is a mapping with keys {', '.join(SPEC_KEYS)}")
    for key in data:
        if key not in SPEC_KEYS:
            raise BatchError(
                f"{path}: unknown key '{key}'{did_you_mean(str(key), SPEC_KEYS)}; "
                f"keys: {', '.join(SPEC_KEYS)}"
            )
    where = str(path)
    scenarios = data.get("scenarios")
    if isinstance(scenarios, str):
        scenarios = [scenarios]
    if not isinstance(scenarios, list) or not all(isinstance(s, str) for s in scenarios):
        raise BatchError(f"{path}: 'scenarios' must be a list of scenario names or launch files")
    args = data.get("args") or {}
    if not isinstance(args, dict):
        raise BatchError(f"{path}: 'args' must be a mapping of argument name to values")
    return BatchSpec(
        scenarios=scenarios,
        args={str(k): parse_values(str(k), v, where) for k, v in args.items()},
        seeds=parse_seeds(data.get("seeds", 0), where),
        duration=_number(data, "duration", DEFAULT_DURATION, where),
        until_goals=bool(data.get("until_goals", True)),
        timeout=_number(data, "timeout", DEFAULT_TIMEOUT, where),
        metrics=data.get("metrics"),
        workdir=path.resolve().parent,
        source=where,
    )


def _number(data: dict, key: str, default: float, where: str) -> float:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BatchError(f"{where}: '{key}' must be a number, got {value!r}")
    return float(value)


def parse_cli_args(items: list[str]) -> dict[str, list[str]]:
    """``--arg NAME=V1,V2`` / ``--arg NAME=A..B`` options: name -> values."""
    out: dict[str, list[str]] = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise BatchError(f"--arg '{item}' is not of the form NAME=V1,V2 or NAME=A..B")
        if name in out:
            raise BatchError(f"--arg '{name}' is given twice; list its values in one --arg")
        out[name] = parse_values(name, value.strip(), "--arg")
    return out
