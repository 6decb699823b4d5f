"""Materials of SDF visuals: colours, ``Gazebo/*`` script names and OGRE material textures."""

from __future__ import annotations

import re
from pathlib import Path

from fleetsim.errors import SimulationError

GAZEBO_COLOURS = {
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/DarkGrey": (0.35, 0.35, 0.35, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/Black": (0.05, 0.05, 0.05, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
    "Gazebo/Orange": (1.0, 0.5, 0.05, 1.0),
    "Gazebo/Wood": (0.55, 0.38, 0.2, 1.0),
    "Gazebo/Purple": (0.5, 0.0, 0.5, 1.0),
    "Gazebo/Turquoise": (0.0, 0.8, 0.8, 1.0),
}


def _text(el, tag: str, default: str) -> str:
    c = el.find(tag)
    return default if c is None or c.text is None else c.text.strip()


def _texture_from_script(script, where: str, find_model) -> str | None:
    """Find the texture image of an OGRE material ``<script><uri>..<name>`` reference."""
    name = _text(script, "name", "")
    dirs: list[Path] = []
    for uri in script.findall("uri"):
        u = (uri.text or "").strip()
        if u.startswith("model://"):
            model, _, rest = u[len("model://") :].partition("/")
            try:
                dirs.append(find_model(model, where) / rest)
            except SimulationError:
                continue
        elif u.startswith("file://"):
            dirs.append(Path(u[len("file://") :]))
    files = [f for d in dirs if d.is_dir() for f in sorted(d.glob("*.material"))]
    for f in files:
        text = f.read_text(errors="replace")
        m = re.search(r"material\s+" + re.escape(name) + r"\s*\{(.*?)\n\}", text, re.S)
        if m:
            t = re.search(r"texture\s+(\S+)", m.group(1))
            if t:
                for d in [f.parent, f.parent.parent / "textures", *dirs]:
                    if (d / t.group(1)).exists():
                        return str(d / t.group(1))
    return None


def material_of(vis, where: str, floats, find_model) -> tuple[tuple | None, str | None]:
    """RGBA and texture image of a ``<visual>``'s ``<material>`` (None where not given).

    ``floats`` and ``find_model`` are ``sdf``'s number parser and ``model://`` lookup, handed
    in because ``sdf`` imports this module.
    """
    rgba = None
    texture = None
    for mat in vis.findall("material"):
        for tag in ("diffuse", "ambient"):
            c = mat.find(tag)
            if c is not None and rgba is None:
                v = floats(c, None, where)
                rgba = (*v[:3], v[3] if len(v) > 3 else 1.0)
        script = mat.find("script")
        if script is not None:
            name = _text(script, "name", "")
            if rgba is None and name in GAZEBO_COLOURS:
                rgba = GAZEBO_COLOURS[name]
            texture = texture or _texture_from_script(script, where, find_model)
        albedo = mat.find("pbr/metal/albedo_map")
        if albedo is not None and albedo.text:
            texture = albedo.text.strip()
    return rgba, texture
