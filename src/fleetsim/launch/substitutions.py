"""roslaunch substitution args: ``$(find)``, ``$(arg)``, ``$(eval)``, ``$(env)``, ``$(optenv)``,
``$(anon)``, ``$(dirname)``, and ROS 2's ``$(var)`` and ``$(find-pkg-share)`` for YAML files.

Semantics follow roslaunch: ``$(eval ...)`` must be the whole attribute; the others may be
embedded in text and are expanded left to right. An ``$(arg x)`` that has no value is an error
naming the arg and where it was used.
"""

from __future__ import annotations

import math
import os
import re
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from fleetsim.errors import LaunchError, did_you_mean

_SUBST = re.compile(r"\$\(([a-z\-]+)((?:\s+[^()\s]+)*)\s*\)")
_EVAL = re.compile(r"\A\$\(eval\s+(.*)\)\Z", re.S)

TRUE_WORDS = {"true", "1"}
FALSE_WORDS = {"false", "0"}


@dataclass
class Context:
    """What substitutions can see: args in scope, the package finder, the current file."""

    args: dict[str, str | None]
    find: Callable[[str], Path]
    filename: Path | None = None
    anon: dict[str, str] = field(default_factory=dict)
    seed: int = 0
    #: args passed in by the includer or the command line, for the file's <arg> declarations
    passed: dict[str, str] = field(default_factory=dict)

    def child(
        self, args: dict[str, str | None], filename: Path | None, passed: dict[str, str]
    ) -> Context:
        return Context(args, self.find, filename, self.anon, self.seed, passed)

    def arg(self, name: str, where: str) -> str:
        if name not in self.args:
            raise LaunchError(
                f"{where}: arg '{name}' is not declared{did_you_mean(name, self.args)}; "
                f'add <arg name="{name}" default="..."/>'
            )
        value = self.args[name]
        if value is None:
            raise LaunchError(
                f"{where}: arg '{name}' is required but not set; pass {name}:=VALUE or give it "
                "a default"
            )
        return value

    def anon_name(self, name: str) -> str:
        # Deterministic anonymous names: the same run and seed give the same names.
        if name not in self.anon:
            self.anon[name] = f"{name}_{zlib.crc32(f'{self.seed}:{name}'.encode()):08x}"
        return self.anon[name]


def _one(kind: str, words: list[str], ctx: Context, where: str) -> str:
    if kind in ("arg", "var"):
        _need(kind, words, 1, where)
        return ctx.arg(words[0], where)
    if kind in ("find", "find-pkg-share", "find-pkg-prefix"):
        _need(kind, words, 1, where)
        return str(ctx.find(words[0]))
    if kind == "env":
        _need(kind, words, 1, where)
        if words[0] not in os.environ:
            raise LaunchError(f"{where}: environment variable '{words[0]}' is not set ($(env))")
        return os.environ[words[0]]
    if kind == "optenv":
        if not words:
            raise LaunchError(f"{where}: $(optenv) needs a variable name")
        return os.environ.get(words[0], " ".join(words[1:]))
    if kind == "anon":
        _need(kind, words, 1, where)
        return ctx.anon_name(words[0])
    if kind == "dirname":
        if ctx.filename is None:
            raise LaunchError(f"{where}: $(dirname) used outside a file")
        return str(Path(ctx.filename).resolve().parent)
    raise LaunchError(
        f"{where}: unknown substitution '$({kind} ...)'"
        f"{did_you_mean(kind, ['arg', 'find', 'env', 'optenv', 'anon', 'dirname', 'eval', 'var'])}"
    )


def _need(kind: str, words: list[str], n: int, where: str) -> None:
    if len(words) != n:
        raise LaunchError(f"{where}: $({kind}) takes {n} argument(s), got {len(words)}: {words}")


def _eval(expr: str, ctx: Context, where: str) -> str:
    # roslaunch's $(eval): a Python expression over the args, with arg(), find(), env(),
    # optenv(), anon(), dirname() and math. Only names, no builtins beyond a few safe ones.
    class _Args(dict):
        def __missing__(self, key):
            # like roslaunch, a bare arg name reads as its converted value ("false" -> False,
            # "3" -> 3); arg('name') gives the string
            if key in ctx.args:
                return auto_value(ctx.arg(key, where))
            raise LaunchError(f"{where}: $(eval {expr}): unknown name '{key}'")

    scope = _Args(
        arg=lambda n: ctx.arg(n, where),
        find=lambda p: str(ctx.find(p)),
        env=lambda n: _one("env", [n], ctx, where),
        optenv=lambda n, d="": os.environ.get(n, d),
        anon=ctx.anon_name,
        dirname=lambda: _one("dirname", [], ctx, where),
        true=True,
        false=False,
        int=int,
        float=float,
        str=str,
        len=len,
        min=min,
        max=max,
        abs=abs,
        round=round,
        **{k: getattr(math, k) for k in ("pi", "sin", "cos", "tan", "sqrt", "radians")},
    )
    try:
        value = eval(expr, {"__builtins__": {}}, scope)
    except LaunchError:
        raise
    except Exception as e:
        raise LaunchError(f"{where}: $(eval {expr}) failed: {type(e).__name__}: {e}") from None
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def substitute(text: str | None, ctx: Context, where: str) -> str | None:
    """Expand every substitution in ``text``; ``where`` names the file, line and attribute."""
    if text is None or "$(" not in text:
        return text
    m = _EVAL.match(text.strip())
    if m:
        return _eval(m.group(1), ctx, where)
    if "$(eval" in text:
        raise LaunchError(f"{where}: $(eval ...) must be the whole attribute value: {text!r}")

    def repl(match: re.Match) -> str:
        return _one(match.group(1), match.group(2).split(), ctx, where)

    out = _SUBST.sub(repl, text)
    if "$(" in out:
        raise LaunchError(f"{where}: substitution does not parse: {text!r}")
    return out


def auto_value(text: str):
    """roslaunch's automatic conversion: int, then float, then true/false, else the string."""
    v = text.strip()
    for conv in (int, float):
        try:
            return conv(v)
        except ValueError:
            pass
    if v.lower() in ("true", "false"):
        return v.lower() == "true"
    return text


def to_bool(value: str, where: str) -> bool:
    """roslaunch's reading of if/unless values: true/1 or false/0 (any case)."""
    v = value.strip().lower()
    if v in TRUE_WORDS:
        return True
    if v in FALSE_WORDS:
        return False
    raise LaunchError(f"{where}: expected true/false (or 1/0), got {value!r}")
