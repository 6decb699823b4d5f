"""The shipped scenarios: launch files under ``fleetsim/assets/launch`` found by name.

Used by ``fleetsim launch NAME``, by batch specs that name scenarios, by benchmarks and tests;
kept here in the launch layer so that the batch runner does not reach into the command line.
"""

from __future__ import annotations

from pathlib import Path

from fleetsim.errors import LaunchError

SCENARIOS = Path(__file__).resolve().parent.parent / "assets" / "launch"


def scenarios() -> dict[str, Path]:
    """Shipped scenarios: name -> launch file."""
    out = {}
    for p in sorted(SCENARIOS.glob("*.launch")) + sorted(SCENARIOS.glob("*.launch.yaml")):
        out[p.name.split(".")[0]] = p
    return out


def resolve_launch_file(name: str) -> Path:
    """A launch file's path, or a shipped scenario's by its name; else a `LaunchError`."""
    p = Path(name)
    if p.is_file():
        return p
    known = scenarios()
    if name in known:
        return known[name]
    raise LaunchError(
        f"'{name}' is neither a launch file nor a shipped scenario; scenarios: "
        f"{', '.join(known) or 'none'} (fleetsim launch --list)"
    )


LAUNCH_SUFFIXES = (".launch", ".xml", ".yaml", ".yml", ".py")


def package_launch_file(pkg: str, name: str) -> Path:
    """roslaunch's ``PACKAGE FILE`` form: the launch file ``name`` in package ``pkg`` (its
    ``launch`` folder first, then anywhere in it); a `LaunchError` naming what it holds."""
    from fleetsim.launch.packages import default_finder

    root = default_finder(Path.cwd())(pkg)
    found = [root / "launch" / name] if (root / "launch" / name).is_file() else []
    found += sorted(p for p in root.rglob(name) if p.is_file() and p not in found)
    if found:
        return found[0]
    held = sorted(p.name for p in root.rglob("*.launch"))
    raise LaunchError(
        f"package '{pkg}' ({root}) has no launch file '{name}'; it has {', '.join(held) or 'none'}"
    )
