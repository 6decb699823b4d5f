"""URDF ``<link>`` contents: inertials, visuals, collisions, geometry and materials.

A mixin of the URDF parser (`fleetsim.description.urdf`), which provides ``attr``, ``floats``,
``number``, ``origin``, ``fail``, ``index`` and ``base_dir``.
"""

from __future__ import annotations

from fleetsim.description.model import (
    Box,
    Collision,
    Cylinder,
    Geometry,
    Inertial,
    Link,
    Material,
    Mesh,
    Sphere,
    Visual,
)
from fleetsim.errors import did_you_mean


class LinkElements:
    def material(self, el, materials, top=False) -> Material:
        name = self.attr(el, "name", required=top, default="")
        color = el.find("color")
        texture = el.find("texture")
        rgba = self.floats(color, "rgba", 4) if color is not None else None
        if rgba is not None and not all(0.0 <= c <= 1.0 for c in rgba):
            self.fail(color, f'color rgba="{color.get("rgba")}" must be four numbers in [0, 1]')
        tex = self.attr(texture, "filename") if texture is not None else None
        if tex is not None:
            tex = self.index.resolve_uri(tex, self.base_dir)
        if rgba is None and tex is None:
            if not top and name in materials:
                return materials[name]
            if top:
                return Material(name)
            self.fail(
                el,
                f"material '{name}' is not defined at robot level and has no <color> or "
                f"<texture>{did_you_mean(name, materials)}",
            )
        return Material(name, rgba, tex)

    def geometry(self, parent) -> Geometry:
        g = parent.find("geometry")
        if g is None or len(g) == 0:
            self.fail(parent, f"<{parent.tag}> has no <geometry> (box, cylinder, sphere or mesh)")
        shape = g[0]
        if shape.tag == "box":
            size = self.floats(shape, "size", 3)
            if min(size) <= 0:
                self.fail(shape, f'box size="{shape.get("size")}" must be positive')
            return Box(size)
        if shape.tag == "cylinder":
            return Cylinder(
                self.number(shape, "radius", minimum=0.0), self.number(shape, "length", minimum=0.0)
            )
        if shape.tag == "sphere":
            return Sphere(self.number(shape, "radius", minimum=0.0))
        if shape.tag == "mesh":
            filename = self.index.resolve_uri(self.attr(shape, "filename"), self.base_dir)
            return Mesh(filename, self.floats(shape, "scale", 3, (1.0, 1.0, 1.0)))
        self.fail(shape, f"unknown geometry <{shape.tag}>; use box, cylinder, sphere or mesh")

    def link(self, el, materials) -> Link:
        link = Link(name=self.attr(el, "name"), source_line=el.sourceline)
        ine = el.find("inertial")
        if ine is not None:
            mass_el = ine.find("mass")
            if mass_el is None:
                self.fail(ine, f"link '{link.name}': <inertial> has no <mass value=...>")
            mass = self.number(mass_el, "value", minimum=0.0)
            it = ine.find("inertia")
            if it is None:
                self.fail(ine, f"link '{link.name}': <inertial> has no <inertia ixx=... izz=...>")
            keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            vals = {k: self.number(it, k) for k in keys}
            for k in ("ixx", "iyy", "izz"):
                if vals[k] < 0:
                    self.fail(it, f"link '{link.name}': inertia {k}={vals[k]:g} is negative")
            link.inertial = Inertial(mass, self.origin(ine), **vals)
        for v in el.findall("visual"):
            mat_el = v.find("material")
            mat = self.material(mat_el, materials) if mat_el is not None else None
            link.visuals.append(Visual(self.origin(v), self.geometry(v), mat, v.get("name")))
        for c in el.findall("collision"):
            link.collisions.append(Collision(self.origin(c), self.geometry(c), c.get("name")))
        return link
