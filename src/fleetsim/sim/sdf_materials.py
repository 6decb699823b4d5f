"""Materials of SDF visuals: colours, ``Gazebo/*`` script names and OGRE material textures."""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from fleetsim.errors import SimulationError
from fleetsim.sim import ogre_scripts, textures

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


def _owner(vis, where: str) -> str:
    """``model '<name>' (<file>)`` of a visual, for error messages."""
    model = next((m.get("name") for m in vis.iterancestors("model")), None)
    return f"model '{model}' ({where})" if model else where


#: fleetsim's stand-in for Gazebo's media folder (``file://media/materials/scripts/...``): the
#: textured ``Gazebo/*`` materials it draws (``Gazebo/Bricks``)
MEDIA_ROOT = Path(__file__).resolve().parent.parent / "assets" / "worlds"
GAZEBO_MATERIALS = MEDIA_ROOT / "media" / "materials" / "scripts" / "gazebo.material"


def _resource_roots() -> list[Path]:
    """Where a relative ``file://`` URI is looked up: GAZEBO_RESOURCE_PATH, then fleetsim's
    media (as Gazebo finds ``file://media/...`` under its share folder)."""
    env = os.environ.get("GAZEBO_RESOURCE_PATH", "")
    return [Path(p) for p in env.split(os.pathsep) if p] + [MEDIA_ROOT]


def _texture_from_script(script, vis, where: str, find_model) -> tuple[str | None, tuple | None]:
    """Texture image and diffuse colour of an OGRE material ``<script><uri>..<name>``
    reference (``ogre_scripts``); (None, None) when no script defines the material (Gazebo's
    plain ``Gazebo/*`` colours are in ``GAZEBO_COLOURS``).

    The URIs name script folders or files: ``model://`` (the model path), ``file://`` (absolute,
    or relative to GAZEBO_RESOURCE_PATH and fleetsim's media), or a path relative to the SDF
    file. As in Gazebo, ``Gazebo/*`` materials are found without a URI too.

    Raises `SimulationError` naming the image, the material and the model when the material
    names a texture image that is not there.
    """
    name = _text(script, "name", "")
    dirs: list[Path] = []
    missing: list[str] = []  # model:// URIs whose model is not found
    for uri in script.findall("uri"):
        u = (uri.text or "").strip()
        if u.startswith("model://"):
            model, _, rest = u[len("model://") :].partition("/")
            try:
                dirs.append(find_model(model, where) / rest)
            except SimulationError:
                missing.append(u)
                continue
        elif u.startswith("file://"):
            path = Path(u[len("file://") :])
            dirs += [path] if path.is_absolute() else [r / path for r in _resource_roots()]
        elif u:
            dirs.append(Path(where).parent / u)
    if name.startswith("Gazebo/"):
        dirs.append(GAZEBO_MATERIALS)
    material = ogre_scripts.find_ogre_material(name, dirs)
    if material is None:
        # a user's script name (Gazebo: "Unable to find material"); a Gazebo/* name fleetsim
        # does not draw is Gazebo's own, not a mistake
        if name and not name.startswith("Gazebo/"):
            looked = ", ".join(str(d) for d in dirs) or "no <uri>"
            lost = f"; no model for {', '.join(missing)} (GAZEBO_MODEL_PATH)" if missing else ""
            warnings.warn(
                f"{_owner(vis, where)}: material script '{name}' is not defined in its "
                f"scripts ({looked}{lost}): drawn without it (a texture it names, such as a "
                "marker's image, will not show)",
                stacklevel=2,
            )
        return None, None
    image = None
    if material.texture is not None:
        image = str(ogre_scripts.texture_file(material, dirs, _owner(vis, where)))
    return image, material.diffuse


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
            image, diffuse = _texture_from_script(script, vis, where, find_model)
            texture = texture or image
            if rgba is None and diffuse is not None:
                rgba = diffuse
        albedo = mat.find("pbr/metal/albedo_map")
        if albedo is not None and albedo.text:
            texture = albedo.text.strip()
            if texture.startswith("model://"):
                model, _, rest = texture[len("model://") :].partition("/")
                texture = str(find_model(model, where) / rest)
            elif not Path(texture).is_absolute():
                texture = str(Path(where).parent / texture)
            textures.checked_image(texture, _owner(vis, where))
    return rgba, texture
