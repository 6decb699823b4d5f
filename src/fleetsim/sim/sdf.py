"""SDF worlds and models (the subset real worlds use) into ``WorldDesc`` / ``ModelDesc``.

Supported: ``<world>`` with ``<include><uri>model://NAME</uri>``, ``<model>`` (``<static>``,
``<pose>``, links with ``<inertial>``, ``<collision>``/``<visual>`` geometry box, cylinder,
sphere, plane and mesh, materials by colour, by ``Gazebo/*`` script name or by a texture from an
OGRE material script), ``<light>``, world ``<plugin>``, ``<gravity>`` and the ``<state>`` block
(saved model poses override the declared ones, as Gazebo does on load). Built-in models:
``ground_plane`` and ``sun``; other models are folders holding ``model.config`` + an SDF file,
found on ``FLEETSIM_MODEL_PATH`` / ``GAZEBO_MODEL_PATH`` and in fleetsim's ``assets/worlds/models``.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

from lxml import etree

from fleetsim.errors import SimulationError
from fleetsim.sim.world import (
    ZERO_POSE,
    GeomDesc,
    LightDesc,
    LinkDesc,
    ModelDesc,
    Pose,
    WorldDesc,
    WorldPluginDesc,
    ground_plane,
    sun,
)

ASSET_MODELS = Path(__file__).resolve().parent.parent / "assets" / "worlds" / "models"

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


def model_path() -> list[Path]:
    """Folders searched for ``model://NAME``: FLEETSIM_MODEL_PATH, GAZEBO_MODEL_PATH, assets."""
    out: list[Path] = []
    for var in ("FLEETSIM_MODEL_PATH", "GAZEBO_MODEL_PATH"):
        out += [Path(p) for p in os.environ.get(var, "").split(os.pathsep) if p]
    return [*out, ASSET_MODELS]


def find_model(name: str, where: str) -> Path:
    """The folder of ``model://name``; error naming the search path when it is missing."""
    for root in model_path():
        folder = root / name
        if (folder / "model.config").exists() or (folder / "model.sdf").exists():
            return folder
    roots = ", ".join(str(p) for p in model_path())
    raise SimulationError(
        f"{where}: model://{name} not found in {roots}; add its folder (model.config + "
        "model.sdf) to FLEETSIM_MODEL_PATH"
    )


def _model_sdf_file(folder: Path) -> Path:
    cfg = folder / "model.config"
    if cfg.exists():
        try:
            root = etree.parse(str(cfg)).getroot()
            for el in root.iter("sdf"):
                if el.text and (folder / el.text.strip()).exists():
                    return folder / el.text.strip()
        except etree.XMLSyntaxError as exc:
            raise SimulationError(f"{cfg}:{exc.lineno}: model.config does not parse") from exc
    return folder / "model.sdf"


def _parse_file(path: Path) -> etree._Element:
    try:
        return etree.parse(str(path)).getroot()
    except OSError as exc:
        raise SimulationError(f"{path}: cannot read SDF file") from exc
    except etree.XMLSyntaxError as exc:
        raise SimulationError(f"{path}:{exc.lineno}: SDF does not parse: {exc.msg}") from exc


def _floats(el, n: int | None, where: str) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in (el.text or "").split())
    except ValueError as exc:
        raise SimulationError(
            f"{where}:{el.sourceline}: <{el.tag}> must hold numbers, got '{el.text}'"
        ) from exc
    if n is not None and len(vals) != n:
        raise SimulationError(
            f"{where}:{el.sourceline}: <{el.tag}> needs {n} numbers, got '{el.text}'"
        )
    return vals


def _pose(el, where: str) -> Pose:
    p = el.find("pose")
    return ZERO_POSE if p is None or not (p.text or "").strip() else _floats(p, 6, where)


def _text(el, tag: str, default: str) -> str:
    c = el.find(tag)
    return default if c is None or c.text is None else c.text.strip()


def _texture_from_script(script, where: str) -> str | None:
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


def _material(vis, where: str) -> tuple[tuple | None, str | None]:
    rgba = None
    texture = None
    for mat in vis.findall("material"):
        for tag in ("diffuse", "ambient"):
            c = mat.find(tag)
            if c is not None and rgba is None:
                v = _floats(c, None, where)
                rgba = (*v[:3], v[3] if len(v) > 3 else 1.0)
        script = mat.find("script")
        if script is not None:
            name = _text(script, "name", "")
            if rgba is None and name in GAZEBO_COLOURS:
                rgba = GAZEBO_COLOURS[name]
            texture = texture or _texture_from_script(script, where)
        albedo = mat.find("pbr/metal/albedo_map")
        if albedo is not None and albedo.text:
            texture = albedo.text.strip()
    return rgba, texture


def _geometry(el, where: str, collide: bool, base: Path) -> GeomDesc | None:
    geo = el.find("geometry")
    if geo is None or len(geo) == 0:
        return None
    shape = geo[0]
    name = el.get("name", "")
    pose = _pose(el, where)
    if shape.tag == "box":
        g = GeomDesc("box", _floats(shape.find("size"), 3, where), pose, name, collide)
    elif shape.tag == "cylinder":
        g = GeomDesc(
            "cylinder",
            (float(_text(shape, "radius", "1")), float(_text(shape, "length", "1"))),
            pose,
            name,
            collide,
        )
    elif shape.tag == "sphere":
        g = GeomDesc("sphere", (float(_text(shape, "radius", "1")),), pose, name, collide)
    elif shape.tag == "plane":
        size = shape.find("size")
        g = GeomDesc(
            "plane",
            _floats(size, 2, where) if size is not None else (100.0, 100.0),
            pose,
            name,
            collide,
        )
    elif shape.tag == "mesh":
        uri = _text(shape, "uri", "")
        if uri.startswith("model://"):
            model, _, rest = uri[len("model://") :].partition("/")
            mesh = str(find_model(model, where) / rest)
        else:
            mesh = str(base / uri.removeprefix("file://"))
        scale = shape.find("scale")
        g = GeomDesc(
            "mesh",
            _floats(scale, 3, where) if scale is not None else (1.0, 1.0, 1.0),
            pose,
            name,
            collide,
            mesh=mesh,
        )
    else:
        warnings.warn(
            f"{where}:{shape.sourceline}: geometry <{shape.tag}> is not supported; "
            f"'{name}' skipped",
            stacklevel=2,
        )
        return None
    if not collide:
        g.rgba, g.texture = _material(el, where)
    else:
        mu = el.find("surface/friction/ode/mu")
        if mu is not None and mu.text:
            g.friction = (float(mu.text), float(_text(el, "surface/friction/ode/mu2", mu.text)))
    return g


def model_from_element(el, where: str, base: Path) -> ModelDesc:
    """A ``ModelDesc`` from an SDF ``<model>`` element."""
    name = el.get("name")
    if not name:
        raise SimulationError(f"{where}:{el.sourceline}: <model> without a name attribute")
    model = ModelDesc(
        name,
        _pose(el, where),
        _text(el, "static", "0") in ("1", "true"),
        source=f"{where}:{el.sourceline}",
    )
    for link in el.findall("link"):
        ld = LinkDesc(link.get("name", "link"), _pose(link, where))
        inertial = link.find("inertial")
        if inertial is not None:
            ld.mass = float(_text(inertial, "mass", "1"))
            ine = inertial.find("inertia")
            if ine is not None:
                ld.inertia = tuple(float(_text(ine, k, "0")) for k in ("ixx", "iyy", "izz"))
        for tag, collide in (("collision", True), ("visual", False)):
            for c in link.findall(tag):
                g = _geometry(c, where, collide, base)
                if g is not None:
                    ld.geoms.append(g)
        model.links.append(ld)
    if el.find("joint") is not None:
        warnings.warn(
            f"{where}:{el.sourceline}: joints of SDF model '{name}' are not "
            "simulated; its links move independently",
            stacklevel=2,
        )
    for sub in el.findall("include") + el.findall("model"):
        warnings.warn(
            f"{where}:{sub.sourceline}: nested models in '{name}' are not supported", stacklevel=2
        )
    return model


def _include(el, where: str) -> ModelDesc | LightDesc:
    uri = _text(el, "uri", "")
    if not uri.startswith("model://"):
        raise SimulationError(
            f"{where}:{el.sourceline}: <include> uri must be model://NAME, got '{uri}'"
        )
    name = uri[len("model://") :].strip("/")
    pose_el = el.find("pose")
    if name == "sun":
        return sun()
    if name == "ground_plane":
        model = ground_plane()
    else:
        folder = find_model(name, f"{where}:{el.sourceline}")
        file = _model_sdf_file(folder)
        root = _parse_file(file)
        mel = root if root.tag == "model" else root.find("model")
        if mel is None:
            raise SimulationError(f"{file}: no <model> element")
        model = model_from_element(mel, str(file), folder)
    model.name = _text(el, "name", model.name)
    if pose_el is not None:
        model.pose = _floats(pose_el, 6, where)
    if el.find("static") is not None:
        model.static = _text(el, "static", "0") in ("1", "true")
    return model


def _light(el, where: str) -> LightDesc:
    d = el.find("direction")
    diffuse = el.find("diffuse")
    return LightDesc(
        el.get("name", "light"),
        _pose(el, where),
        el.get("type", "directional") == "directional",
        _floats(d, 3, where) if d is not None else (-0.5, 0.1, -0.9),
        _floats(diffuse, None, where)[:3] if diffuse is not None else (0.8, 0.8, 0.8),
    )


def _plugin_params(el) -> dict[str, str]:
    return {c.tag: (c.text or "").strip() for c in el if isinstance(c.tag, str)}


def load_sdf_world(path: str | Path) -> WorldDesc:
    """Parse an SDF ``.world`` file (``<sdf><world>``) into a ``WorldDesc``."""
    path = Path(path)
    root = _parse_file(path)
    where = str(path)
    world = root if root.tag == "world" else root.find("world")
    if world is None:
        raise SimulationError(f"{where}:{root.sourceline}: no <world> element in <{root.tag}>")
    desc = WorldDesc(name=world.get("name", "default"), source=where)
    for el in world:
        if not isinstance(el.tag, str):
            continue
        if el.tag == "model":
            desc.models.append(model_from_element(el, where, path.parent))
        elif el.tag == "include":
            item = _include(el, where)
            (desc.lights if isinstance(item, LightDesc) else desc.models).append(item)
        elif el.tag == "light":
            desc.lights.append(_light(el, where))
        elif el.tag == "plugin":
            desc.plugins.append(
                WorldPluginDesc(el.get("name", ""), el.get("filename", ""), _plugin_params(el))
            )
        elif el.tag == "gravity":
            desc.gravity = _floats(el, 3, where)
    state = world.find("state")
    if state is not None:
        by_name = {m.name: m for m in desc.models}
        for sm in state.findall("model"):
            m = by_name.get(sm.get("name", ""))
            if m is not None and sm.find("pose") is not None:
                m.pose = _pose(sm, where)
    names = [m.name for m in desc.models]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise SimulationError(
            f"{where}: duplicate model names {sorted(dup)}; give each <include> a unique <name>"
        )
    return desc


def load_sdf_model(text: str, source: str = "<string>") -> ModelDesc:
    """Parse SDF text holding one ``<model>`` (as ``spawn_sdf_model`` receives it)."""
    try:
        root = etree.fromstring(text.encode())
    except etree.XMLSyntaxError as exc:
        raise SimulationError(f"{source}:{exc.lineno}: SDF does not parse: {exc.msg}") from exc
    el = root if root.tag == "model" else root.find("model")
    if el is None:
        raise SimulationError(f"{source}: no <model> element in the SDF")
    base = Path(source).parent if source != "<string>" else Path.cwd()
    return model_from_element(el, source, base)
