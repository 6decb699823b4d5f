"""Fixtures for message tests: populated instances of any message class."""

from __future__ import annotations

import numpy as np
import pytest

from fleetsim.msgs.fields import Prim, SeqSpec


def _prim_value(spec: Prim, rng: np.random.Generator):
    if spec.py is bool:
        return bool(rng.integers(2))
    if spec.py is int:
        return int(rng.integers(spec.lo, spec.hi, endpoint=True, dtype=spec.dtype))
    if spec.py is float:
        x = rng.normal() * 100
        return float(np.float32(x)) if spec.name == "float32" else float(x)
    return "".join(rng.choice(list("abcxyz_/é1"), size=int(rng.integers(0, 8))))


def _value(spec, rng: np.random.Generator, depth: int):
    if isinstance(spec, Prim):
        return _prim_value(spec, rng)
    if isinstance(spec, SeqSpec):
        n = spec.length if spec.length is not None else int(rng.integers(1, 4))
        if spec.is_array:
            return np.array([_prim_value(spec.elem, rng) for _ in range(n)], spec.elem.dtype)
        return [_value(spec.elem, rng, depth + 1) for _ in range(n)]
    return populate(spec, rng, depth + 1)


def populate(cls: type, rng: np.random.Generator, depth: int = 0):
    """An instance of ``cls`` with every field set to a random non-default value."""
    return cls(**{f: _value(spec, rng, depth) for f, spec in cls.__msgfields__})


@pytest.fixture
def populated():
    """``populated(cls, seed=0)`` -> a random populated instance of a message class."""

    def make(cls: type, seed: int = 0):
        return populate(cls, np.random.default_rng(seed))

    return make


def own_definition(typename: str) -> list[str]:
    """The lines of a type's own ros2msg definition (without its dependencies)."""
    from fleetsim.msgs import msgdef

    return msgdef(typename).split("=" * 80)[0].strip().splitlines()


@pytest.fixture
def own_def():
    """``own_def(typename)`` -> the lines of the type's own ros2msg definition."""
    return own_definition
