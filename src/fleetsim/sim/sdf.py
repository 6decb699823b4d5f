"""SDF worlds and models (the subset real worlds use) into ``WorldDesc`` / ``ModelDesc``.

Supported: ``<world>`` with ``<include><uri>model://NAME</uri>``, ``<model>`` (``<static>``,
``<pose>``, links with ``<inertial>``, ``<collision>``/``<visual>`` geometry box, cylinder,
sphere, plane and mesh, materials by colour, by ``Gazebo/*`` script name or by a texture from an
OGRE material script, ``sdf_materials``), ``<light>``, world ``<plugin>``, ``<gravity>`` and the
``<state>`` block (saved model poses override the declared ones, as Gazebo does on load). Poses
follow SDFormat (``sdf_poses``): an ``<include>``'s ``<pose>`` (radians) and ``<name>`` replace
the model's own, ``<placement_frame>`` places a named link there, ``relative_to`` names a frame
of the same scope, nested ``<model>``/``<include>`` elements are flattened into
``<nested>::<link>`` links with composed poses. Built-in models:
``ground_plane`` and ``sun``; other models are folders holding ``model.config`` + an SDF file,
found on ``FLEETSIM_MODEL_PATH`` / ``GAZEBO_MODEL_PATH`` and in fleetsim's ``assets/worlds/models``.
"""

from __future__ import annotations

import os
import warnings
from contextvars import ContextVar
from pathlib import Path

from lxml import etree

from fleetsim.errors import SimulationError
from fleetsim.sim.sdf_materials import GAZEBO_COLOURS, material_of
from fleetsim.sim.sdf_poses import compose, element_pose, inverse, poses_in_scope
from fleetsim.sim.world import (
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

__all__ = ["GAZEBO_COLOURS", "load_sdf_model", "load_sdf_world", "model_from_element"]

ASSET_MODELS = Path(__file__).resolve().parent.parent / "assets" / "worlds" / "models"


#: while a world file is read: the model paths its packages export, found once for the file
_exported: ContextVar[list[Path] | None] = ContextVar("sdf_exported_model_paths", default=None)


def exported_model_paths(near: Path | None) -> list[Path]:
    """``<export><gazebo_ros gazebo_model_path="${prefix}/models"/>`` of the packages around
    ``near`` and on the package path, as gazebo_ros's launch files add them to Gazebo's path
    (``rospack plugins --attrib=gazebo_model_path gazebo_ros``)."""
    from fleetsim.description.packages import env_package_path, packages_above, packages_under

    pkgs: dict[str, Path] = {}
    if near is not None:
        pkgs.update(packages_above(near))
    for root in env_package_path():
        for name, folder in packages_under(root).items():
            pkgs.setdefault(name, folder)
    out: list[Path] = []
    for folder in pkgs.values():
        try:
            root = etree.parse(str(folder / "package.xml")).getroot()
        except (OSError, etree.XMLSyntaxError):
            continue
        for el in root.iterfind("export/gazebo_ros"):
            value = el.get("gazebo_model_path")
            if value:
                for part in value.replace("${prefix}", str(folder)).split(os.pathsep):
                    if part.strip() and Path(part.strip()) not in out:
                        out.append(Path(part.strip()))
    return out


def model_path() -> list[Path]:
    """Folders searched for ``model://NAME``: FLEETSIM_MODEL_PATH, GAZEBO_MODEL_PATH, the
    ``gazebo_model_path`` exports of the world file's package and of the package path, assets."""
    out: list[Path] = []
    for var in ("FLEETSIM_MODEL_PATH", "GAZEBO_MODEL_PATH"):
        out += [Path(p) for p in os.environ.get(var, "").split(os.pathsep) if p]
    exported = _exported.get()
    if exported is None:  # not inside a world file: the package path's exports only
        exported = exported_model_paths(None)
    return [*out, *exported, ASSET_MODELS]


def find_model(name: str, where: str) -> Path:
    """The folder of ``model://name``; error naming the search path when it is missing."""
    for root in model_path():
        folder = root / name
        if (folder / "model.config").exists() or (folder / "model.sdf").exists():
            return folder
    roots = ", ".join(str(p) for p in model_path())
    raise SimulationError(
        f"{where}: model://{name} not found in {roots}; add its folder (model.config + "
        "model.sdf) to GAZEBO_MODEL_PATH, or export it from your package.xml as "
        '<export><gazebo_ros gazebo_model_path="${prefix}/models"/></export>'
    )


def _model_sdf_file(folder: Path) -> Path:
    """The model's SDF file: of the ``<sdf version=...>`` entries of ``model.config`` whose
    file exists, the one of the highest version (as Gazebo picks it), else ``model.sdf``."""
    cfg = folder / "model.config"
    if cfg.exists():
        try:
            root = etree.parse(str(cfg)).getroot()
            found = [
                (_version(el.get("version", "")), i, folder / el.text.strip())
                for i, el in enumerate(root.iter("sdf"))
                if el.text and (folder / el.text.strip()).exists()
            ]
            if found:
                return max(found)[2]
        except etree.XMLSyntaxError as exc:
            raise SimulationError(f"{cfg}:{exc.lineno}: model.config does not parse") from exc
    return folder / "model.sdf"


def _version(text: str) -> tuple[int, ...]:
    try:
        return tuple(int(p) for p in text.strip().split("."))
    except ValueError:
        return ()


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
    """An element's own pose numbers (``relative_to`` is resolved by the caller)."""
    return element_pose(el, where)[0]


def _text(el, tag: str, default: str) -> str:
    c = el.find(tag)
    return default if c is None or c.text is None else c.text.strip()


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
        g.rgba, g.texture = material_of(el, where, _floats, find_model)
    else:
        mu = el.find("surface/friction/ode/mu")
        if mu is not None and mu.text:
            g.friction = (float(mu.text), float(_text(el, "surface/friction/ode/mu2", mu.text)))
    return g


def model_from_element(el, where: str, base: Path) -> ModelDesc:
    """A ``ModelDesc`` from an SDF ``<model>`` element.

    Links are placed in the model frame, ``relative_to`` resolved among the model's links,
    ``<frame>`` elements and nested models; collision and visual poses are expressed in their
    link (``relative_to`` another frame of the model is converted). Nested ``<model>`` and
    ``<include>`` elements are flattened: their links become ``<nested>::<link>`` links of this
    model, placed by the composed poses.
    """
    name = el.get("name")
    if not name:
        raise SimulationError(f"{where}:{el.sourceline}: <model> without a name attribute")
    pose, relative_to = element_pose(el, where)
    model = ModelDesc(
        name,
        pose,
        _text(el, "static", "0") in ("1", "true"),
        source=f"{where}:{el.sourceline}",
        relative_to=relative_to,
    )
    nested = [model_from_element(sub, where, base) for sub in el.findall("model")]
    for inc in el.findall("include"):
        item = _include(inc, where)
        if isinstance(item, ModelDesc):
            nested.append(item)
    frames: dict[str, tuple] = {}
    for link in el.findall("link"):
        frames[link.get("name", "link")] = element_pose(link, where)
    for fr in el.findall("frame"):
        fpose, rel = element_pose(fr, where)
        frames[fr.get("name", "")] = (fpose, rel or fr.get("attached_to", ""))
    for sub in nested:
        frames[sub.name] = (sub.pose, sub.relative_to)
    placed = poses_in_scope(frames, where, f"model '{name}'", ("__model__",))
    for link in el.findall("link"):
        lname = link.get("name", "link")
        ld = LinkDesc(lname, placed[lname])
        inertial = link.find("inertial")
        if inertial is not None:
            ld.mass = float(_text(inertial, "mass", "1"))
            ine = inertial.find("inertia")
            if ine is not None:
                ld.inertia = tuple(float(_text(ine, k, "0")) for k in ("ixx", "iyy", "izz"))
        for tag, collide in (("collision", True), ("visual", False)):
            for c in link.findall(tag):
                g = _geometry(c, where, collide, base)
                if g is None:
                    continue
                rel = element_pose(c, where)[1]
                if rel and rel != lname:
                    if rel not in placed:
                        raise SimulationError(
                            f"{where}:{c.sourceline}: <pose relative_to='{rel}'> of {tag} "
                            f"'{g.name}' names no frame of model '{name}' "
                            f"(frames there: {', '.join(sorted(placed))})"
                        )
                    g.pose = compose(inverse(ld.pose), compose(placed[rel], g.pose))
                ld.geoms.append(g)
        model.links.append(ld)
    for sub in nested:
        for link in sub.links:
            link.name = f"{sub.name}::{link.name}"
            link.pose = compose(placed[sub.name], link.pose)
            model.links.append(link)
    model.frames = placed
    if el.find("joint") is not None:
        warnings.warn(
            f"{where}:{el.sourceline}: joints of SDF model '{name}' are not "
            "simulated; its links move independently",
            stacklevel=2,
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
    if pose_el is not None:  # the include's pose replaces the model's own (Gazebo's rule)
        model.pose, model.relative_to = element_pose(el, where)
    placement = _text(el, "placement_frame", "")
    if placement:  # SDF 1.8: the pose places this frame of the model, not its origin
        if placement not in model.frames:
            raise SimulationError(
                f"{where}:{el.sourceline}: <placement_frame>{placement}</placement_frame> names "
                f"no link or frame of model '{model.name}' "
                f"(there: {', '.join(sorted(model.frames))})"
            )
        model.pose = compose(model.pose, inverse(model.frames[placement]))
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
    token = _exported.set(exported_model_paths(path.resolve()))
    try:
        return _load_sdf_world(path)
    finally:
        _exported.reset(token)


def _load_sdf_world(path: Path) -> WorldDesc:
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
    frames = {m.name: (m.pose, m.relative_to) for m in desc.models}
    for fr in world.findall("frame"):
        fpose, rel = element_pose(fr, where)
        frames.setdefault(fr.get("name", ""), (fpose, rel or fr.get("attached_to", "")))
    placed = poses_in_scope(frames, where, f"world '{desc.name}'", ("world",))
    for m in desc.models:
        m.pose, m.relative_to = placed[m.name], ""
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
        # gazebo_ros spawns ``<sdf><world><include><uri>model://NAME</uri></include></world>``
        # as well (grobot's spawn_marker_on_robot sends this)
        inc = root.find(".//include")
        if inc is None:
            raise SimulationError(
                f"{source}: no <model> element (nor an <include> of one) in the SDF"
            )
        model = _include(inc, source)
        if not isinstance(model, ModelDesc):
            raise SimulationError(f"{source}:{inc.sourceline}: the <include> is not a model")
        model.relative_to = ""
        return model
    base = Path(source).parent if source != "<string>" else Path.cwd()
    model = model_from_element(el, source, base)
    if model.relative_to not in ("", "world"):
        raise SimulationError(
            f"{source}:{el.sourceline}: <pose relative_to='{model.relative_to}'> of a spawned "
            f"model '{model.name}': a spawned model's pose is in the world frame"
        )
    return model
