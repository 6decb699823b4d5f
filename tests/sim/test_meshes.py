"""COLLADA meshes: parsing (transforms, units, polylists, errors, cache) and use in the engine."""

import itertools
import os
import warnings

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.build import add_sdf_model, new_world_spec
from fleetsim.sim.meshes import (
    clear_mesh_cache,
    triangle_mesh_from_collada,
)
from fleetsim.sim.world import GeomDesc, LinkDesc, ModelDesc

# unit cube centred at the origin; triangles counter-clockwise seen from outside
CUBE = np.array(list(itertools.product((-0.5, 0.5), repeat=3)))[:, ::-1]  # x fastest
# CUBE rows: 0(-,-,-) 1(+,-,-) 2(-,+,-) 3(+,+,-) 4(-,-,+) 5(+,-,+) 6(-,+,+) 7(+,+,+)
TRIS = "0 2 3 0 3 1 4 5 7 4 7 6 0 1 5 0 5 4 2 6 7 2 7 3 0 4 6 0 6 2 1 3 7 1 7 5"
QUADS = "0 2 3 1 4 5 7 6 0 1 5 4 2 6 7 3 0 4 6 2 1 3 7 5"
VTX = '<input semantic="VERTEX" source="#cube-vtx" offset="0"/>'
TRIANGLES = f'<triangles count="12">{VTX}<p>{TRIS}</p></triangles>'
POLYLIST = f'<polylist count="6">{VTX}<vcount>{"4 " * 6}</vcount><p>{QUADS}</p></polylist>'
POLYGONS = (
    '<polygons count="6">'
    + VTX
    + "".join(f"<p>{' '.join(q)}</p>" for q in np.array(QUADS.split()).reshape(6, 4))
    + "</polygons>"
)
LINES = f'<lines count="2">{VTX}<p>0 1 1 3</p></lines>'
PLAIN = '<node id="n"><instance_geometry url="#cube"/></node>'


def collada(prims=TRIANGLES, nodes=PLAIN, unit="", up="Z_UP", library_nodes="", scale=1.0):
    """COLLADA 1.4.1 text of the unit cube (times ``scale``) under ``nodes``."""
    pos = " ".join(f"{v:g}" for v in (CUBE * scale).ravel())
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>{unit}<up_axis>{up}</up_axis></asset>
  <library_geometries><geometry id="cube" name="cube"><mesh>
    <source id="cube-pos"><float_array id="cube-pos-array" count="24">{pos}</float_array>
      <technique_common><accessor source="#cube-pos-array" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="cube-vtx"><input semantic="POSITION" source="#cube-pos"/></vertices>
    {prims}
  </mesh></geometry></library_geometries>
  {library_nodes}
  <library_visual_scenes><visual_scene id="Scene">{nodes}</visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


def write(tmp_path, text, name="m.dae"):
    path = tmp_path / name
    path.write_text(text)
    return path


def bounds(v):
    return np.stack([v.min(axis=0), v.max(axis=0)])


def signed_volume(v, f):
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_unit_cube_with_node_transform(tmp_path):
    nodes = (
        '<node id="n"><translate>1 2 3</translate><rotate>0 0 1 90</rotate>'
        '<scale>2 1 1</scale><instance_geometry url="#cube"/></node>'
    )
    v, f = triangle_mesh_from_collada(write(tmp_path, collada(nodes=nodes)))
    assert v.shape == (8, 3) and v.dtype == np.float64
    assert f.shape == (12, 3) and f.dtype == np.int32
    np.testing.assert_allclose(bounds(v), [[0.5, 1, 2.5], [1.5, 3, 3.5]], atol=1e-6)  # float32
    assert signed_volume(v, f) == pytest.approx(2.0)  # outward winding, volume 2 x 1 x 1
    assert not v.flags.writeable and not f.flags.writeable


def test_node_hierarchy_instance_node_and_two_instances(tmp_path):
    library = (
        '<library_nodes><node id="lib"><translate>0 0 1</translate>'
        '<instance_geometry url="#cube"/></node></library_nodes>'
    )
    nodes = (
        '<node id="parent"><translate>10 0 0</translate>'
        '<node id="child"><scale>1 1 3</scale><instance_node url="#lib"/></node></node>'
        '<node id="other"><matrix>1 0 0 0  0 1 0 -5  0 0 1 0  0 0 0 1</matrix>'
        '<instance_geometry url="#cube"/></node>'
    )
    v, f = triangle_mesh_from_collada(write(tmp_path, collada(nodes=nodes, library_nodes=library)))
    assert v.shape == (16, 3) and f.shape == (24, 3) and f.max() == 15
    np.testing.assert_allclose(bounds(v[:8]), [[9.5, -0.5, 1.5], [10.5, 0.5, 4.5]], atol=1e-6)
    np.testing.assert_allclose(bounds(v[8:]), [[-0.5, -5.5, -0.5], [0.5, -4.5, 0.5]])


def test_unit_meter_scales_to_metres(tmp_path):
    text = collada(unit='<unit name="centimeter" meter="0.01"/>', scale=100.0)
    v, f = triangle_mesh_from_collada(write(tmp_path, text))
    np.testing.assert_allclose(bounds(v), [[-0.5] * 3, [0.5] * 3])


@pytest.mark.parametrize("prims", [POLYLIST, POLYGONS], ids=["polylist", "polygons"])
def test_polygons_are_triangulated_and_lines_ignored(tmp_path, prims):
    v, f = triangle_mesh_from_collada(write(tmp_path, collada(prims=prims + LINES)))
    assert f.shape == (12, 3)
    assert signed_volume(v, f) == pytest.approx(1.0)


def test_up_axis_is_ignored(tmp_path):
    nodes = '<node id="n"><translate>0 5 0</translate><instance_geometry url="#cube"/></node>'
    y_up, _ = triangle_mesh_from_collada(write(tmp_path, collada(nodes=nodes, up="Y_UP"), "y.dae"))
    z_up, _ = triangle_mesh_from_collada(write(tmp_path, collada(nodes=nodes), "z.dae"))
    np.testing.assert_array_equal(y_up, z_up)
    np.testing.assert_allclose(bounds(y_up), [[-0.5, 4.5, -0.5], [0.5, 5.5, 0.5]])


def exporter_style_collada():
    """The cube as modelling tools write it: interleaved VERTEX/NORMAL/TEXCOORD indices, a bound
    material whose texture image is missing, and a physics scene beside the visual scene."""
    normals = "0 0 -1 0 0 1 0 -1 0 0 1 0 -1 0 0 1 0 0"
    tris = np.array(TRIS.split(), int).reshape(12, 3)
    p = " ".join(f"{v} {i // 2} {k}" for i, t in enumerate(tris) for k, v in enumerate(t))
    prims = (
        '<triangles count="12" material="paint">'
        '<input offset="0" semantic="VERTEX" source="#cube-vtx"/>'
        '<input offset="1" semantic="NORMAL" source="#cube-nrm"/>'
        '<input offset="2" semantic="TEXCOORD" source="#cube-uv" set="0"/>'
        f"<p>{p}</p></triangles>"
    )
    sources = (
        f'<source id="cube-nrm"><float_array id="cube-nrm-array" count="18">{normals}'
        '</float_array><technique_common><accessor source="#cube-nrm-array" count="6" '
        'stride="3"><param name="X" type="float"/><param name="Y" type="float"/>'
        '<param name="Z" type="float"/></accessor></technique_common></source>'
        '<source id="cube-uv"><float_array id="cube-uv-array" count="6">0 0 1 0 1 1'
        '</float_array><technique_common><accessor source="#cube-uv-array" count="3" '
        'stride="2"><param name="S" type="float"/><param name="T" type="float"/>'
        "</accessor></technique_common></source>"
    )
    nodes = (
        '<node id="n"><translate sid="t">0 0 0.5</translate><rotate sid="r">0 0 1 0</rotate>'
        '<instance_geometry url="#cube"><bind_material><technique_common>'
        '<instance_material symbol="paint" target="#paint-mat"/>'
        "</technique_common></bind_material></instance_geometry></node>"
    )
    libraries = (
        '<library_images><image id="img"><init_from>missing.jpg</init_from></image>'
        '</library_images><library_effects><effect id="paint-fx"><profile_COMMON>'
        '<newparam sid="surf"><surface type="2D"><init_from>img</init_from></surface>'
        '</newparam><newparam sid="samp"><sampler2D><source>surf</source></sampler2D>'
        '</newparam><technique sid="common"><phong><diffuse><texture texture="samp" '
        'texcoord="UV"/></diffuse></phong></technique></profile_COMMON></effect>'
        '</library_effects><library_materials><material id="paint-mat">'
        '<instance_effect url="#paint-fx"/></material></library_materials>'
    )
    text = collada(prims=sources + prims, nodes=nodes, unit='<unit meter="1.00" name="meter"/>')
    return text.replace("<library_geometries>", libraries + "<library_geometries>")


def test_exporter_style_file_with_normals_uvs_and_a_missing_texture(tmp_path):
    v, f = triangle_mesh_from_collada(write(tmp_path, exporter_style_collada()))
    np.testing.assert_allclose(bounds(v), [[-0.5, -0.5, 0], [0.5, 0.5, 1]], atol=1e-6)
    assert f.shape == (12, 3) and signed_volume(v, f) == pytest.approx(1.0)


def test_broken_references_are_reported(tmp_path):
    text = exporter_style_collada().replace('target="#paint-mat"', 'target="#nope"')
    with pytest.raises(SimulationError, match=r"nope\.dae' holds no triangles.*#nope not found"):
        triangle_mesh_from_collada(write(tmp_path, text, "nope.dae"))
    second = '<node id="m"><instance_geometry url="#cube"/></node>'
    text = text.replace("</visual_scene>", second + "</visual_scene>")
    with pytest.warns(UserWarning, match=r"parts that did not load are left out.*#nope"):
        v, f = triangle_mesh_from_collada(write(tmp_path, text, "half.dae"))
    assert f.shape == (12, 3)


def test_broken_files_name_the_file_and_reason(tmp_path):
    bad = write(tmp_path, "<COLLADA><library_geometries>", "broken.dae")
    with pytest.raises(SimulationError, match=r"broken\.dae' does not parse"):
        triangle_mesh_from_collada(bad)
    lines = write(tmp_path, collada(prims=LINES), "lines.dae")
    with pytest.raises(SimulationError, match=r"lines\.dae' holds no triangles"):
        triangle_mesh_from_collada(lines)
    with pytest.raises(SimulationError, match=r"nothere\.dae' cannot be read"):
        triangle_mesh_from_collada(tmp_path / "nothere.dae")
    zero = write(tmp_path, collada(unit='<unit meter="0"/>'), "zero.dae")
    with pytest.raises(SimulationError, match=r"zero\.dae.*must be a positive number"):
        triangle_mesh_from_collada(zero)


def test_parsed_once_and_reread_when_the_file_changes(tmp_path):
    clear_mesh_cache()
    path = write(tmp_path, collada())
    first = triangle_mesh_from_collada(path)
    assert triangle_mesh_from_collada(path)[0] is first[0]
    path.write_text(collada(scale=2.0))
    st_ = path.stat()
    os.utime(path, ns=(st_.st_atime_ns, st_.st_mtime_ns + 10**9))
    again = triangle_mesh_from_collada(path)
    np.testing.assert_allclose(bounds(again[0]), [[-1] * 3, [1] * 3])


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-3, 3, allow_nan=False), min_size=12, max_size=12).filter(
        lambda m: abs(np.linalg.det(np.reshape(m, (3, 4))[:, :3])) > 1e-2
    ),
    st.integers(0, 10**9),
)
def test_matrix_transform_property(tmp_path_factory, m, key):
    """Any affine ``<matrix>`` (mirrors too): vertices are M @ v, winding stays outward."""
    mat = np.vstack([np.reshape(m, (3, 4)), [0, 0, 0, 1]])
    text = " ".join(repr(float(x)) for x in mat.ravel())
    nodes = f'<node id="n"><matrix>{text}</matrix><instance_geometry url="#cube"/></node>'
    path = write(tmp_path_factory.mktemp("prop"), collada(nodes=nodes), f"m{key}.dae")
    v, f = triangle_mesh_from_collada(path)
    np.testing.assert_allclose(v, CUBE @ mat[:3, :3].T + mat[:3, 3], atol=1e-5)  # float32
    vol = signed_volume(v, f)
    assert vol == pytest.approx(abs(np.linalg.det(mat[:3, :3])), rel=1e-3, abs=1e-4)
    assert vol > 0


def mesh_model(path, scale=(1.0, 1.0, 1.0), static=True, collide=True):
    geom = GeomDesc("mesh", scale, name="shape", collide=collide, mesh=str(path))
    return ModelDesc("thing", (0, 0, 0, 0, 0, 0), static, [LinkDesc("body", geoms=[geom])])


def test_missing_and_unread_mesh_files(tmp_path):
    spec = new_world_spec()
    with pytest.raises(SimulationError, match=r"'.*gone\.dae' of geom 'shape' in 'thing/body' "):
        add_sdf_model(spec, mesh_model(tmp_path / "gone.dae"))
    with pytest.raises(SimulationError, match=r"gone\.stl' of geom 'shape'.*does not exist"):
        add_sdf_model(spec, mesh_model(tmp_path / "gone.stl"))
    ogre = write(tmp_path, "binary", "shape.mesh")
    with pytest.warns(UserWarning, match=r"reads STL/OBJ/MSH/DAE meshes; the shape is skipped"):
        add_sdf_model(spec, mesh_model(ogre))
    assert spec.compile().ngeom == 0


SPHERE = (
    "<sdf><model name='s'><link name='l'><inertial><mass>0.5</mass></inertial><collision "
    "name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision>"
    "</link></model></sdf>"
)


def test_dae_collision_box_is_seen_by_laser_and_holds_a_sphere(tmp_path, diffbot):
    from fleetsim.sim.plugins.laser import LaserPlugin

    # a 1 m cube in centimetres, scaled by the SDF to 0.4 x 1 x 1 m, centred at (2, 0, 0.5)
    dae = write(tmp_path, collada(unit='<unit meter="0.01"/>', scale=100.0), "crate.dae")
    sdf = (
        "<sdf><model name='crate'><static>true</static><link name='l'><collision name='c'>"
        f"<geometry><mesh><uri>file://{dae}</uri><scale>0.4 1 1</scale></mesh></geometry>"
        "</collision></link></model></sdf>"
    )
    e = Engine(None)
    r = e.spawn_robot("r", diffbot, (0, 0, 0, 0, 0, 0))
    e.spawn_sdf("crate", sdf, (2.0, 0, 0.5, 0, 0, 0))
    laser = next(p for p in r.plugins if isinstance(p, LaserPlugin))
    scan = e.lasers.measure(e, [laser], e.time)[0]
    assert scan.ranges[180] == pytest.approx(2.0 - 0.2 - 0.1, abs=1e-3)  # laser 0.1 ahead
    e.spawn_sdf("on_top", SPHERE, (2.15, 0.4, 1.5, 0, 0, 0))  # inside the 0.2 half-width
    e.spawn_sdf("beside", SPHERE, (2.35, 0.0, 1.5, 0, 0, 0))  # just past it
    e.advance(1.5)
    assert e.model_pose("on_top")[0][2] == pytest.approx(1.1, abs=5e-3)
    assert e.model_pose("beside")[0][2] == pytest.approx(0.1, abs=5e-3)


def test_urdf_robot_with_dae_visual_spawns_and_renders(tmp_path):
    dae = write(tmp_path, collada(), "body.dae")
    urdf = f"""<robot name="meshbot">
      <link name="base_link">
        <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0"
          izz="0.01"/></inertial>
        <collision><origin xyz="0 0 0.1"/><geometry><box size="0.2 0.2 0.2"/></geometry>
        </collision>
        <visual><origin xyz="0 0 0.25"/><geometry><mesh filename="{dae}" scale="0.5 0.5 0.5"/>
          </geometry><material name="red"><color rgba="1 0 0 1"/></material></visual>
      </link></robot>"""
    e = Engine(None)
    e.spawn_robot("m1", write(tmp_path, urdf, "meshbot.urdf"), (0, 0, 0, 0, 0, 0))
    e.spawn_robot("m2", write(tmp_path, urdf, "meshbot.urdf"), (3, 0, 0, 0, 0, 0))
    e.advance(0.1)
    m = e.model
    meshes = [g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]
    assert len(meshes) == 2 and all(m.geom_contype[g] == 0 for g in meshes)
    assert m.nmesh == 1  # one asset for both robots
    centre = e.data.geom_xpos[meshes[0]]
    np.testing.assert_allclose(centre, [0, 0, 0.25], atol=2e-3)
    verts = m.mesh_vert[m.mesh_vertadr[0] : m.mesh_vertadr[0] + m.mesh_vertnum[0]]
    np.testing.assert_allclose(np.ptp(verts, axis=0), [0.5, 0.5, 0.5], atol=1e-6)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = [0, 0, 0.25]
    cam.distance, cam.elevation, cam.azimuth = 2.0, -30.0, 90.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        renderer = e.renderer(64, 48)
    renderer.update_scene(e.data, cam)
    img = renderer.render().astype(int)
    red = (img[..., 0] > 120) & (img[..., 1] < 60) & (img[..., 2] < 60)
    assert 0.05 < red.mean() < 0.6  # the half-metre cube fills a good part of the view
    e.delete_model("m1")
    e.spawn_robot("m1", write(tmp_path, urdf, "meshbot.urdf"), (0, 0, 0, 0, 0, 0))
    assert e.model.nmesh == 1  # spawned again under the same name, on the same asset
    e.close()
