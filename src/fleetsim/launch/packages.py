"""``$(find pkg)`` for launch files: the description package index plus fleetsim's assets.

fleetsim's own assets (robots, worlds, maps, launch files) are packages under
``fleetsim/assets``; users' packages come from the folders around the launch file and from
``FLEETSIM_PACKAGE_PATH`` / ``ROS_PACKAGE_PATH``. ``$(find xacro)`` names the built-in xacro
processor, so ``command="$(find xacro)/xacro ..."`` runs in process.
"""

from __future__ import annotations

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
