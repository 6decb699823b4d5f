""":class:`Robot` → URDF XML text (what ``fleetsim urdf export`` writes).

Links, joints and materials are written from the model; ``<gazebo>`` and ``<transmission>``
elements are written back verbatim from the text they were parsed from.
"""

from __future__ import annotations

from lxml import etree

from fleetsim.description.model import (
    Box,
    Cylinder,
    Geometry,
    Joint,
    Link,
    Material,
    Mesh,
    Origin,
    Robot,
    Sphere,
)


def _num(v: float) -> str:
    s = repr(float(v))
    return s[:-2] if s.endswith(".0") else s


def _nums(vs) -> str:
    return " ".join(_num(v) for v in vs)


def _origin(parent, o: Origin) -> None:
    if o != Origin():
        etree.SubElement(parent, "origin", xyz=_nums(o.xyz), rpy=_nums(o.rpy))


def _geometry(parent, g: Geometry) -> None:
    geo = etree.SubElement(parent, "geometry")
    if isinstance(g, Box):
        etree.SubElement(geo, "box", size=_nums(g.size))
    elif isinstance(g, Cylinder):
        etree.SubElement(geo, "cylinder", radius=_num(g.radius), length=_num(g.length))
    elif isinstance(g, Sphere):
        etree.SubElement(geo, "sphere", radius=_num(g.radius))
    elif isinstance(g, Mesh):
        attrs = {"filename": g.filename}
        if g.scale != (1.0, 1.0, 1.0):
            attrs["scale"] = _nums(g.scale)
        etree.SubElement(geo, "mesh", **attrs)


def _material(parent, m: Material, by_name: bool) -> None:
    el = etree.SubElement(parent, "material", name=m.name)
    if by_name:
        return
    if m.rgba is not None:
        etree.SubElement(el, "color", rgba=_nums(m.rgba))
    if m.texture is not None:
        etree.SubElement(el, "texture", filename=m.texture)


def _link(root, link: Link, materials: dict[str, Material]) -> None:
    el = etree.SubElement(root, "link", name=link.name)
    if link.inertial is not None:
        i = link.inertial
        ie = etree.SubElement(el, "inertial")
        _origin(ie, i.origin)
        etree.SubElement(ie, "mass", value=_num(i.mass))
        etree.SubElement(
            ie,
            "inertia",
            ixx=_num(i.ixx),
            ixy=_num(i.ixy),
            ixz=_num(i.ixz),
            iyy=_num(i.iyy),
            iyz=_num(i.iyz),
            izz=_num(i.izz),
        )
    for v in link.visuals:
        ve = etree.SubElement(el, "visual", **({"name": v.name} if v.name else {}))
        _origin(ve, v.origin)
        _geometry(ve, v.geometry)
        if v.material is not None:
            _material(ve, v.material, by_name=materials.get(v.material.name) == v.material)
    for c in link.collisions:
        ce = etree.SubElement(el, "collision", **({"name": c.name} if c.name else {}))
        _origin(ce, c.origin)
        _geometry(ce, c.geometry)


def _joint(root, j: Joint) -> None:
    el = etree.SubElement(root, "joint", name=j.name, type=j.type)
    _origin(el, j.origin)
    etree.SubElement(el, "parent", link=j.parent)
    etree.SubElement(el, "child", link=j.child)
    if j.type not in ("fixed", "floating"):
        etree.SubElement(el, "axis", xyz=_nums(j.axis))
    if j.limit is not None:
        lim = j.limit
        etree.SubElement(
            el,
            "limit",
            lower=_num(lim.lower),
            upper=_num(lim.upper),
            effort=_num(lim.effort),
            velocity=_num(lim.velocity),
        )
    if j.dynamics is not None:
        etree.SubElement(
            el, "dynamics", damping=_num(j.dynamics.damping), friction=_num(j.dynamics.friction)
        )
    if j.mimic is not None:
        etree.SubElement(
            el,
            "mimic",
            joint=j.mimic.joint,
            multiplier=_num(j.mimic.multiplier),
            offset=_num(j.mimic.offset),
        )


def urdf_from_robot(robot: Robot) -> str:
    """URDF text for ``robot``, pretty-printed, with an XML declaration."""
    root = etree.Element("robot", name=robot.name)
    for m in robot.materials.values():
        _material(root, m, by_name=False)
    for link in robot.links.values():
        _link(root, link, robot.materials)
    for j in robot.joints.values():
        _joint(root, j)
    for block in [*robot.gazebo, *robot.transmissions]:
        if block.xml:
            root.append(etree.fromstring(block.xml))
    etree.indent(root, space="  ")
    body = etree.tostring(root, encoding="unicode")
    return '<?xml version="1.0" encoding="utf-8"?>\n' + body + "\n"
