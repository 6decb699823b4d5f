"""Finding ROS-style packages (folders holding a ``package.xml``) without ROS.

Search order for ``$(find pkg)`` and ``package://pkg/...``: explicit folders given by the caller,
the folders above the file being read, ``FLEETSIM_PACKAGE_PATH``, ``ROS_PACKAGE_PATH`` and last
fleetsim's own ``assets/robots``. The first package found with a name wins, as in rospack.
"""

from __future__ import annotations

import difflib
import os
from collections.abc import Iterable
from pathlib import Path

from lxml import etree

from fleetsim.errors import DescriptionError

ASSET_ROBOTS = Path(__file__).resolve().parent.parent / "assets" / "robots"
ENV_VARS = ("FLEETSIM_PACKAGE_PATH", "ROS_PACKAGE_PATH")
_SKIP_DIRS = {".git", "__pycache__", ".venv", "node_modules", "build", "devel", "install"}


def package_name(package_xml: Path) -> str:
    """The ``<name>`` inside a package.xml (the folder name when the file has none)."""
    try:
        root = etree.parse(str(package_xml)).getroot()
    except etree.XMLSyntaxError as exc:
        raise DescriptionError(
            f"{package_xml}: not valid XML ({exc}); fix the package.xml"
        ) from exc
    name = root.findtext("name")
    return name.strip() if name and name.strip() else package_xml.parent.name


def packages_under(root: Path) -> dict[str, Path]:
    """Packages found by walking ``root`` (not descending into a package once found)."""
    found: dict[str, Path] = {}
    root = Path(root)
    if not root.is_dir():
        return found
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d not in _SKIP_DIRS and not d.startswith("."))
        if "package.xml" in filenames or "CATKIN_IGNORE" in filenames:
            if "package.xml" in filenames:
                pkg = Path(dirpath)
                found.setdefault(package_name(pkg / "package.xml"), pkg.resolve())
            dirnames[:] = []
    return found


def packages_above(path: Path) -> dict[str, Path]:
    """Packages that contain ``path`` (walking up the folders, nearest first)."""
    found: dict[str, Path] = {}
    p = Path(path).resolve()
    for folder in [p, *p.parents] if p.is_dir() else p.parents:
        xml = folder / "package.xml"
        if xml.is_file():
            found.setdefault(package_name(xml), folder)
    return found


def env_package_path() -> list[Path]:
    """Folders listed in ``FLEETSIM_PACKAGE_PATH`` then ``ROS_PACKAGE_PATH``."""
    out: list[Path] = []
    for var in ENV_VARS:
        for part in os.environ.get(var, "").split(os.pathsep):
            if part.strip():
                out.append(Path(part.strip()).expanduser())
    return out


def similar_names(word: str, choices: Iterable[str], n: int = 3) -> str:
    """``" (did you mean 'a' or 'b'?)"`` for up to ``n`` close names: spelled alike (difflib),
    or one containing the other (``lizi_description`` and ``lizi``); ``""`` when none is."""
    choices = sorted(set(choices))
    close = difflib.get_close_matches(word, choices, n=n, cutoff=0.6)
    w = word.lower()
    for c in choices:
        lc = c.lower()
        if len(close) < n and c not in close and min(len(lc), len(w)) >= 3 and (lc in w or w in lc):
            close.append(c)
    if not close:
        return ""
    return " (did you mean " + " or ".join(f"'{c}'" for c in close) + "?)"


class PackageIndex:
    """Name → folder map built once from a search path; ``find`` raises a helpful error."""

    def __init__(self, package_path: Iterable[Path] | None = None, near: Path | None = None):
        self.packages: dict[str, Path] = {}
        self.searched: list[Path] = []
        roots = [Path(p) for p in (package_path or [])]
        for root in roots:
            self._add(packages_above(root) if (root / "package.xml").is_file() else {})
            self._add(packages_under(root))
            self.searched.append(root)
        if near is not None:
            self._add(packages_above(near))
            self.searched.append(Path(near).resolve().parent)
        for root in [*env_package_path(), ASSET_ROBOTS]:
            self._add(packages_under(root))
            self.searched.append(root)

    def _add(self, found: dict[str, Path]) -> None:
        for name, path in found.items():
            self.packages.setdefault(name, path)

    def find(self, name: str) -> Path:
        """The folder of package ``name``."""
        try:
            return self.packages[name]
        except KeyError:
            where = ", ".join(str(p) for p in self.searched)
            hint = similar_names(name, self.packages)
            raise DescriptionError(
                f"package '{name}' not found{hint}; searched {where}. "
                "Add its parent folder to FLEETSIM_PACKAGE_PATH (or ROS_PACKAGE_PATH), or pass "
                "package_path=[...]"
            ) from None

    def get_path(self, name: str) -> str:
        """``find`` as a string (the interface xacrodoc's package finder expects)."""
        return self.find(name).as_posix()

    def resolve_uri(self, uri: str, base_dir: Path | None = None) -> str:
        """An absolute file path for ``package://pkg/rel``, ``file:///abs`` or a relative path."""
        if uri.startswith("package://"):
            rest = uri[len("package://") :]
            pkg, _, rel = rest.partition("/")
            return (self.find(pkg) / rel).as_posix()
        if uri.startswith("file://"):
            return uri[len("file://") :]
        p = Path(uri)
        if not p.is_absolute() and base_dir is not None:
            p = Path(base_dir) / p
        return p.as_posix()
