"""roslaunch substitution args: ``$(find)``, ``$(arg)``, ``$(eval)``, ``$(env)``, ``$(optenv)``,
``$(anon)``, ``$(dirname)``, and ROS 2's ``$(var)`` and ``$(find-pkg-share)`` for YAML files.

Semantics follow roslaunch's ``substitution_args.py``: ``$(eval ...)`` must be the whole
attribute and sees every Python builtin, the ``math`` module, ``true``/``false``, ``arg()``,
``find()``, ``env()``, ``optenv()``, ``anon()``, ``dirname()`` and the args by bare name (both
converted as roslaunch's ``auto`` type); the others may be embedded in text and are expanded
left to right. An ``$(arg x)`` that has no value is an error naming the arg and where it was used.
Where fleetsim differs on purpose: ``$(anon x)`` is deterministic (same seed, same name).
"""

from __future__ import annotations

import math
import os
import re
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from fleetsim.errors import LaunchError, did_you_mean

_SUBST = re.compile(r"\$\(([a-z\-]+)((?:\s+[^()\s]+)*)\s*\)")
_EVAL = re.compile(r"\A\$\(eval\s+(.*)\)\Z", re.S)

TRUE_WORDS = {"true", "1"}
FALSE_WORDS = {"false", "0"}
#: the substitution commands roslaunch (ROS 1) knows; XML files may use only these
ROS1_KINDS = frozenset({"arg", "find", "env", "optenv", "anon", "dirname", "eval"})
ALL_KINDS = ROS1_KINDS | {"var", "find-pkg-share", "find-pkg-prefix"}


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
    #: the file was included with pass_all_args="true": re-declaring or overriding a passed
    #: arg is allowed, and passed args the file does not declare are ignored (ROS Melodic+)
    pass_all_args: bool = False
    #: the substitution commands this frontend knows
    kinds: frozenset[str] = ALL_KINDS

    def child(
        self,
        args: dict[str, str | None],
        filename: Path | None,
        passed: dict[str, str],
        pass_all_args: bool = False,
    ) -> Context:
        return replace(
            self, args=args, filename=filename, passed=passed, pass_all_args=pass_all_args
        )

    def scoped(self) -> Context:
        """A ``<group>``'s context: args declared inside it are not seen after it (roslaunch
        copies the arg dictionary into each group)."""
        return replace(self, args=dict(self.args), passed=dict(self.passed), pass_all_args=False)

    def value_of(self, name: str) -> str | None:
        """The arg's current value: its declared value, else the one passed in."""
        value = self.args.get(name)
        return value if value is not None else self.passed.get(name)

    def arg(self, name: str, where: str) -> str:
        # roslaunch reads args from one dictionary holding declared and passed values, so a
        # passed arg is readable even where it is not declared (pass_all_args relies on it)
        if name not in self.args and name not in self.passed:
            raise LaunchError(
                f"{where}: arg '{name}' is not declared{did_you_mean(name, self.args)}; "
                f'add <arg name="{name}" default="..."/>'
            )
        value = self.value_of(name)
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
    if kind not in ctx.kinds:
        raise LaunchError(
            f"{where}: unknown substitution '$({kind} ...)'"
            f"{did_you_mean(kind, sorted(ctx.kinds))}; roslaunch knows "
            f"{', '.join(sorted(ctx.kinds))}"
        )
    if kind in ("arg", "var"):
        _need(kind, words, 1, where)
        return ctx.arg(words[0], where)
    if kind in ("find", "find-pkg-share", "find-pkg-prefix"):
        _need(kind, words, 1, where)
        return _find(words[0], ctx, where)
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


def _find(pkg: str, ctx: Context, where: str) -> str:
    try:
        return str(ctx.find(pkg))
    except LaunchError as e:
        raise LaunchError(f"{where}: {e}") from None


def _need(kind: str, words: list[str], n: int, where: str) -> None:
    if len(words) != n:
        raise LaunchError(f"{where}: $({kind}) takes {n} argument(s), got {len(words)}: {words}")


def _eval(expr: str, ctx: Context, where: str) -> str:
    # roslaunch's $(eval): a Python expression whose names are, in this order, the helper
    # functions and math, then the args (auto-converted), then Python's builtins; no '__'.
    if "__" in expr:
        raise LaunchError(f"{where}: $(eval ...) may not contain double underscore expressions")
    functions = {k: v for k, v in vars(math).items() if not k.startswith("_")}
    functions.update(
        arg=lambda n: auto_value(ctx.arg(n, where)),
        find=lambda p: _find(p, ctx, where),
        env=lambda n: _one("env", [n], ctx, where),
        optenv=lambda n, d="": os.environ.get(n, d),
        anon=ctx.anon_name,
        dirname=lambda: _one("dirname", [], ctx, where),
        true=True,
        false=False,
    )

    class _Names(dict):
        def __missing__(self, key):
            if key in ctx.args or key in ctx.passed:
                return auto_value(ctx.arg(key, where))
            raise KeyError(key)  # on to Python's builtins, as roslaunch's lookup falls through

    try:
        value = eval(expr, {}, _Names(functions))
    except LaunchError:
        raise
    except NameError as e:
        raise LaunchError(
            f"{where}: $(eval {expr}): {e}; declare it with <arg> or call arg('name')"
        ) from None
    except Exception as e:
        raise LaunchError(f"{where}: $(eval {expr}) failed: {type(e).__name__}: {e}") from None
    return str(value)


def substitute(text: str | None, ctx: Context, where: str) -> str | None:
    """Expand every substitution in ``text``; ``where`` names the file, line and attribute."""
    if text is None or "$(" not in text:
        return text
    m = _EVAL.match(text)
    if m and "eval" in ctx.kinds:
        return _eval(m.group(1), ctx, where)
    if "$(eval" in text:
        raise LaunchError(f"{where}: $(eval ...) must be the whole attribute value: {text!r}")

    # roslaunch expands in two passes: everything but $(find) first, then $(find), so an arg
    # whose value is "$(find pkg)/x" (passed as name:=...) is found too
    def repl(match: re.Match, finds: bool) -> str:
        if (match.group(1) == "find") != finds:
            return match.group(0)
        return _one(match.group(1), match.group(2).split(), ctx, where)

    out = _SUBST.sub(lambda m: repl(m, False), text)
    out = _SUBST.sub(lambda m: repl(m, True), out)
    if "$(" in out:
        raise LaunchError(f"{where}: substitution does not parse: {text!r}")
    return out


def auto_value(text: str):
    """roslaunch's ``auto`` conversion (``loader.convert_value``): text with a '.' that parses
    as a float is a float; else text without '_' that parses as an int is an int; else
    true/false (any case) is a bool; else the text itself ("1e3", "inf" and "1_000" stay
    strings, as in roslaunch)."""
    try:
        if "." in text:
            return float(text)
        if "_" not in text:
            return int(text)
    except ValueError:
        pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def to_bool(value: str, where: str) -> bool:
    """roslaunch's reading of if/unless values: true/1 or false/0 (any case)."""
    v = value.strip().lower()
    if v in TRUE_WORDS:
        return True
    if v in FALSE_WORDS:
        return False
    raise LaunchError(f"{where}: expected true/false (or 1/0), got {value!r}")


def strict_bool(value: str, where: str) -> bool:
    """roslaunch's reading of respawn, required, clear_params, pass_all_args and subst_value:
    only true or false (any case); 1/0, which if/unless accept, are an error here."""
    v = value.lower()
    if v == "true":
        return True
    if v == "false":
        return False
    if not value:
        raise LaunchError(f"{where}: a bool value must be non-empty (true or false)")
    raise LaunchError(f"{where}: invalid bool value {value!r}; roslaunch accepts true or false")
