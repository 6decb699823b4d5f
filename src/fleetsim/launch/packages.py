"""``$(find pkg)`` for launch files: the description package index plus fleetsim's assets.

fleetsim's own assets (robots, worlds, maps, launch files) are packages under
``fleetsim/assets``; users' packages come from the folders around the launch file and from
``FLEETSIM_PACKAGE_PATH`` / ``ROS_PACKAGE_PATH``. ``$(find xacro)`` names the built-in xacro
processor, so ``command="$(find xacro)/xacro ..."`` (or the older ``xacro.py``) runs in
process. Lizi is there under its own name (``lizi``) and under the lesson's
(``lizi_description``, ``urdf/lizi.urdf``).

A package or file that is not there is reported with the names that look like it.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable
from pathlib import Path

from fleetsim.description.packages import PackageIndex
from fleetsim.errors import DescriptionError, LaunchError

ASSETS = Path(__file__).resolve().parent.parent / "assets"
#: what $(find xacro) expands to; the launch frontend runs `<this>/xacro` commands in process
XACRO_PKG = Path("/fleetsim-builtin/xacro")


def default_finder(near: Path | None = None) -> Callable[[str], Path]:
    index = PackageIndex([ASSETS], near=near)

    def find(pkg: str) -> Path:
        if pkg == "xacro":
            return XACRO_PKG
        try:
            return index.find(pkg)
        except DescriptionError as e:
            raise LaunchError(str(e)) from None

    return find


def similar_files(path: Path, n: int = 3) -> str:
    """A hint for a path that does not exist: ``"; did you mean .../lizi.urdf.xacro?"``.

    Looks in the deepest folder of ``path`` that exists, for entries spelled like the first
    missing part (difflib) or starting with it (``lizi.urdf`` -> ``lizi.urdf.xacro``); lists a
    small folder's entries when none is close; ``""`` when nothing helps."""
    path = Path(path)
    base = path.parent
    while not base.is_dir() and base != base.parent:
        base = base.parent
    if not base.is_dir() or path == base:
        return ""
    missing = path.relative_to(base).parts[0] if path.is_relative_to(base) else path.name
    try:
        entries = sorted(p.name for p in base.iterdir() if not p.name.startswith("."))
    except OSError:
        return ""
    close = difflib.get_close_matches(missing, entries, n=n, cutoff=0.75)
    stem = missing.split(".")[0]
    for e in entries:
        if len(close) < n and e not in close and (e.startswith(missing) or e.split(".")[0] == stem):
            close.append(e)
    if close:
        return "; did you mean " + " or ".join(str(base / c) for c in close) + "?"
    if entries and len(entries) <= 12:
        return f"; {base} holds {', '.join(entries)}"
    return ""
