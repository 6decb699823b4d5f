"""``<gazebo>`` and ``<transmission>`` elements of a URDF → :mod:`fleetsim.description.model`.

Gazebo extensions are kept in the form gazebo_ros users write them: ``<gazebo reference="link">``
holds surface properties (``mu1``, ``mu2``, ``kp``, ``kd``, ``material`` ...) and ``<sensor>``
elements with their plugins; ``<gazebo>`` without a reference holds model plugins.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from lxml import etree

from fleetsim.description.model import GazeboBlock, Origin, PluginSpec, Robot, SensorSpec
from fleetsim.errors import did_you_mean

if TYPE_CHECKING:
    from fleetsim.description.urdf import _Parser

_TRUE = {"1", "true", "True", "TRUE"}
_FALSE = {"0", "false", "False", "FALSE"}


def element_dict(el) -> dict:
    """Nested dict of an element's children: leaves map to their stripped text.

    Attributes of an element with children appear as ``'@name'`` keys; a tag repeated inside one
    element becomes a list of its values.
    """
    out: dict = {f"@{k}": v for k, v in el.attrib.items()}
    for child in el:
        if not isinstance(child.tag, str):
            continue
        value = element_dict(child) if len(child) else (child.text or "").strip()
        if len(child) == 0 and child.attrib and not value:
            value = {f"@{k}": v for k, v in child.attrib.items()}
        if child.tag in out:
            prev = out[child.tag]
            out[child.tag] = [*prev, value] if isinstance(prev, list) else [prev, value]
        else:
            out[child.tag] = value
    return out


def parse_plugin(el, p: _Parser) -> PluginSpec:
    params = element_dict(el)
    for key in ("@name", "@filename"):
        params.pop(key, None)
    return PluginSpec(
        name=p.attr(el, "name", required=False, default="") or "",
        filename=p.attr(el, "filename"),
        params=params,
        source_line=el.sourceline,
    )


def _bool(el, tag: str, p: _Parser, default: bool) -> bool:
    child = el.find(tag)
    if child is None:
        return default
    text = (child.text or "").strip()
    if text in _TRUE:
        return True
    if text in _FALSE:
        return False
    return p.fail(child, f"<{tag}>{text}</{tag}> is not a boolean; write true or false")


def parse_sensor(el, reference: str | None, p: _Parser) -> SensorSpec:
    name = p.attr(el, "name")
    stype = p.attr(el, "type")
    rate_el = el.find("update_rate")
    rate = 0.0
    if rate_el is not None:
        try:
            rate = float((rate_el.text or "").strip())
        except ValueError:
            p.fail(rate_el, f"sensor '{name}': update_rate '{rate_el.text}' is not a number")
        if rate < 0:
            p.fail(rate_el, f"sensor '{name}': update_rate {rate:g} must be >= 0 (0: every step)")
    pose = Origin()
    pose_el = el.find("pose")
    if pose_el is not None:
        try:
            vals = [float(v) for v in (pose_el.text or "").split()]
        except ValueError:
            vals = []
        if len(vals) != 6:
            p.fail(pose_el, f"sensor '{name}': <pose>{pose_el.text}</pose> is not 'x y z r p y'")
        pose = Origin(tuple(vals[:3]), tuple(vals[3:]))
    skip = {"update_rate", "always_on", "visualize", "pose", "plugin", "ray", "camera"}
    ray = el.find("ray")
    camera = el.find("camera")
    return SensorSpec(
        name=name,
        type=stype,
        reference=reference,
        update_rate=rate,
        always_on=_bool(el, "always_on", p, False),
        visualize=_bool(el, "visualize", p, False),
        pose=pose,
        ray=element_dict(ray) if ray is not None else None,
        camera=element_dict(camera) if camera is not None else None,
        extra={
            c.tag: element_dict(c) if len(c) else (c.text or "").strip()
            for c in el
            if isinstance(c.tag, str) and c.tag not in skip
        },
        plugins=[parse_plugin(pl, p) for pl in el.findall("plugin")],
        source_line=el.sourceline,
    )


def parse_gazebo(el, p: _Parser) -> GazeboBlock:
    reference = el.get("reference")
    block = GazeboBlock(
        reference=reference,
        xml=etree.tostring(el, encoding="unicode", with_tail=False),
        source_line=el.sourceline,
    )
    for child in el:
        if not isinstance(child.tag, str):
            continue
        if child.tag == "plugin":
            block.plugins.append(parse_plugin(child, p))
        elif child.tag == "sensor":
            block.sensors.append(parse_sensor(child, reference, p))
        elif len(child):
            block.properties[child.tag] = etree.tostring(child, encoding="unicode").strip()
        else:
            block.properties[child.tag] = (child.text or "").strip()
    return block


def parse_transmission(el, p: _Parser, robot: Robot):
    from fleetsim.description.model import Transmission

    name = p.attr(el, "name")
    type_el = el.find("type")
    ttype = (type_el.text or "").strip() if type_el is not None else el.get("type", "")
    if not ttype:
        p.fail(
            el,
            f"transmission '{name}' has no <type> (e.g. transmission_interface/SimpleTransmission)",
        )
    tr = Transmission(
        name=name,
        type=ttype,
        xml=etree.tostring(el, encoding="unicode", with_tail=False),
        source_line=el.sourceline,
    )
    for j in el.findall("joint"):
        jname = p.attr(j, "name")
        if jname not in robot.joints:
            p.fail(
                j,
                f"transmission '{name}' names joint '{jname}', which is not defined"
                f"{did_you_mean(jname, robot.joints)}",
            )
        hw = [(h.text or "").strip() for h in j.findall("hardwareInterface")]
        if not hw or not hw[0]:
            p.fail(
                j,
                f"transmission '{name}': joint '{jname}' has no <hardwareInterface> "
                "(e.g. hardware_interface/EffortJointInterface)",
            )
        tr.joints.append((jname, hw[0]))
    for a in el.findall("actuator"):
        red = a.find("mechanicalReduction")
        try:
            reduction = float((red.text or "1").strip()) if red is not None else 1.0
        except ValueError:
            p.fail(red, f"transmission '{name}': mechanicalReduction '{red.text}' is not a number")
        tr.actuators.append((p.attr(a, "name"), reduction))
    return tr
