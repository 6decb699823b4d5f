"""Robots from URDF into MuJoCo: inertial details."""

import warnings

import numpy as np
import pytest

from fleetsim.description import parse_urdf
from fleetsim.sim import Engine

URDF = """<robot name="r">
  <link name="base"><inertial><mass value="2"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="sensor"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="sensor"/>
    <origin xyz="0.5 0.3 0.2"/></joint>
  <link name="arm"/>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0.2 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"""


def test_a_massless_link_keeps_its_centre_of_mass_at_its_origin():
    """A link without <inertial> gets a tiny mass at its own origin, not at its offset (MuJoCo 4
    would otherwise compile the unset centre to the body's position in its parent)."""
    e = Engine(None)
    # said, naming the link and its joint; the fixed 'sensor' link without one is not
    with pytest.warns(UserWarning) as said:
        e.spawn_robot("r", parse_urdf(URDF), (3.0, 4.0, 0.5, 0, 0, 0))
    texts = [str(w.message) for w in said]
    assert len(texts) == 1, texts
    assert "link 'arm' (moved by revolute joint 'hinge') has no <inertial>" in texts[0]
    arm = e.model.body("r/arm").id
    np.testing.assert_allclose(e.model.body_ipos[arm], [0.0, 0.0, 0.0])
    base = e.model.body("r/base").id
    np.testing.assert_allclose(e.model.body_ipos[base], [0.1, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("inertial", "words"),
    [
        ('<mass value="0"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>',
         "has mass 0"),
        ('<mass value="1"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/>',
         "has inertia ixx 0 iyy 0 izz 0"),
        ('<mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>', None),
    ],
)  # fmt: skip
def test_a_moving_link_without_mass_or_inertia_is_warned_about(inertial, words):
    text = URDF.replace(
        '<link name="arm"/>', f'<link name="arm"><inertial>{inertial}</inertial></link>'
    )
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        Engine(None).spawn_robot("r", parse_urdf(text), (0, 0, 0.5, 0, 0, 0))
    texts = [str(w.message) for w in said if "link 'arm'" in str(w.message)]
    assert texts == ([] if words is None else [texts[0]]) and (words is None or words in texts[0])


def test_a_moving_link_whose_mass_is_on_a_link_fixed_to_it_is_not_warned_about():
    """Gazebo lumps a fixed child's inertial into its parent (a wheel link with its mass on a
    fixed hub link is valid there), and fleetsim's welded child keeps its mass."""
    text = URDF.replace(
        "</robot>",
        '<link name="hub"><inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" '
        'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<joint name="hub_j" type="fixed"><parent link="arm"/><child link="hub"/></joint>'
        "</robot>",
    )
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        Engine(None).spawn_robot("r", parse_urdf(text), (0, 0, 0.5, 0, 0, 0))
    assert not [w for w in said if "link 'arm'" in str(w.message)]
