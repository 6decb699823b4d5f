"""Textures as Gazebo applies them: OGRE scripts, images, the image stretched on each face."""

import mujoco
import numpy as np
import pytest
from PIL import Image

from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.sdf import load_sdf_model
from fleetsim.sim.textures import box_uv_mesh

pytestmark = pytest.mark.usefixtures("in_tmp_dir")


def assert_no_mujoco_warnings(engine):
    assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}


def test_box_uv_mesh_puts_the_whole_image_on_each_face():
    v, f, t = box_uv_mesh((2.0, 4.0, 6.0))
    assert v.shape == (24, 3) and f.shape == (12, 3) and t.shape == (24, 2)
    np.testing.assert_allclose(np.abs(v).max(axis=0), [1.0, 2.0, 3.0])
    for face in range(6):
        quad = v[4 * face : 4 * face + 4]
        axis = np.flatnonzero(np.ptp(quad, axis=0) == 0)  # the face's constant coordinate
        assert len(axis) == 1
        normal = np.zeros(3)
        normal[axis[0]] = np.sign(quad[0, axis[0]])
        for tri in f[2 * face : 2 * face + 2]:  # counter-clockwise seen from outside
            a, b, c = v[tri]
            assert np.dot(np.cross(b - a, c - a), normal) > 0
        uv = t[4 * face : 4 * face + 4]
        assert sorted(map(tuple, uv)) == [(0, 0), (0, 1), (1, 0), (1, 1)]  # stretched, once
    # the +x face reads upright from outside: image top (v=0) at +z, image left (u=0) at -y
    px = v[20:24]
    top = px[t[20:24, 1] == 0]
    left = px[t[20:24, 0] == 0]
    assert np.all(top[:, 2] > 0) and np.all(left[:, 1] < 0)


QUADRANTS = """<sdf version="1.6"><model name="sign"><static>true</static><link name="link">
  <visual name="v"><geometry><box><size>0.01 1.0 0.5</size></box></geometry>
    <material><script><uri>file://{dir}</uri><name>Sign/Quadrants</name></script></material>
  </visual></link></model></sdf>"""


def quadrant_model(tmp_path, image="quad.png", write=True):
    if write:
        img = np.zeros((40, 40, 3), np.uint8)
        img[:20, :20] = (255, 0, 0)  # top left red
        img[:20, 20:] = (0, 255, 0)  # top right green
        img[20:, :20] = (0, 0, 255)  # bottom left blue
        img[20:, 20:] = 255  # bottom right white
        Image.fromarray(img).save(tmp_path / image)
    (tmp_path / "sign.material").write_text(
        "material Sign/Quadrants\n{\n technique\n {\n  pass\n  {\n   texture_unit\n   {\n"
        f"    texture {image}\n   }}\n  }}\n }}\n}}\n"
    )
    return QUADRANTS.format(dir=tmp_path)


def render_from(engine, lookat, azimuth, distance, size=(160, 120)):
    r = engine.renderer(*size)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = lookat
    cam.distance, cam.azimuth, cam.elevation = distance, azimuth, 0.0
    opt = mujoco.MjvOption()
    opt.geomgroup[3] = 0  # collision shapes hidden, as the camera plugin renders
    r.update_scene(engine.data, camera=cam, scene_option=opt)
    return r.render().copy()


def test_texture_is_stretched_over_the_face_as_gazebo_draws_it(tmp_path):
    e = Engine(None)
    e.spawn_sdf("sign", load_sdf_model(quadrant_model(tmp_path)), (0, 0, 1.0, 0, 0, 0))
    img = render_from(e, (0, 0, 1.0), 180.0, 1.2)  # from +x, looking back along -x
    assert_no_mujoco_warnings(e)
    Image.fromarray(img).save(tmp_path / "sign.png")
    h, w = img.shape[:2]
    distance = 1.2 - 0.005  # to the sign's front face
    px = h / (2 * distance * np.tan(np.radians(e.model.vis.global_.fovy) / 2))  # pixels per m
    cy, cx = h // 2, w // 2
    dy, dx = round(0.125 * px), round(0.25 * px)  # quadrant centres of the 1.0 x 0.5 m face
    samples = {
        "top left": img[cy - dy, cx - dx],
        "top right": img[cy - dy, cx + dx],
        "bottom left": img[cy + dy, cx - dx],
        "bottom right": img[cy + dy, cx + dx],
    }
    dominant = {k: int(np.argmax(v)) if np.ptp(v) > 60 else "white" for k, v in samples.items()}
    assert dominant == {"top left": 0, "top right": 1, "bottom left": 2, "bottom right": "white"}
    # stretched once over the face, not repeated by size: along the top row, red gives way to
    # green once, at the face's middle
    row = img[cy - dy, cx - round(0.45 * px) : cx + round(0.45 * px)].astype(int)
    green = row[:, 1] > row[:, 0]
    switches = np.flatnonzero(np.diff(green.astype(int)))
    assert len(switches) == 1 and abs(switches[0] - len(row) / 2) <= 2


def test_missing_texture_image_names_the_file_the_material_and_the_model(tmp_path):
    text = quadrant_model(tmp_path, "gone.png", write=False)
    with pytest.raises(
        SimulationError,
        match=r"model 'sign' \(<string>\): texture image 'gone.png' of material "
        r"'Sign/Quadrants' \(.*sign.material:1\) not found; looked in ",
    ):
        load_sdf_model(text)


def test_a_material_name_no_script_defines_is_warned_about(tmp_path):
    """A typo in the material's <name> (a marker's MyMarkr for MyMarker) had drawn the plate
    blank without a word, and the follower never saw the marker; Gazebo says it cannot find
    the material. A name the scripts define, or one of Gazebo's colours, is not warned about."""
    import warnings

    text = quadrant_model(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        load_sdf_model(text)
        load_sdf_model(text.replace("Sign/Quadrants", "Gazebo/Red"))
    with pytest.warns(
        UserWarning, match=r"model 'sign' \(<string>\): material script 'Sign/Quadrnts' is not "
    ):
        load_sdf_model(text.replace("Sign/Quadrants", "Sign/Quadrnts"))
    with pytest.warns(UserWarning, match=r"no model for model://no_such_model/scripts"):
        load_sdf_model(text.replace(f"file://{tmp_path}", "model://no_such_model/scripts"))


def test_urdf_texture_and_missing_image(tmp_path):
    from fleetsim.description import parse_urdf

    quadrant_model(tmp_path)
    urdf = f"""<robot name="r"><link name="base"><visual><geometry><box size="0.1 0.2 0.3"/>
      </geometry><material name="m"><texture filename="{tmp_path}/quad.png"/></material>
      </visual></link></robot>"""
    e = Engine(None)
    e.spawn_robot("r", parse_urdf(urdf), (0, 0, 1, 0, 0, 0))
    geom = next(i for i in range(e.model.ngeom) if e.model.geom(i).name.startswith("r/base"))
    assert e.model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_MESH
    assert e.model.geom_matid[geom] >= 0 and e.model.ntex >= 1
    e.advance(0.1)
    assert_no_mujoco_warnings(e)
    with pytest.raises(SimulationError, match=r"'r2/base/visual': texture image '.*nope.png' not"):
        e.spawn_robot("r2", parse_urdf(urdf.replace("quad.png", "nope.png")))


SIGN_DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="1"/><up_axis>Z_UP</up_axis></asset>
<library_images><image id="img"><init_from>quad.png</init_from></image></library_images>
<library_effects><effect id="fx"><profile_COMMON>
 <newparam sid="surf"><surface type="2D"><init_from>img</init_from></surface></newparam>
 <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
 <technique sid="c"><lambert><diffuse><texture texture="samp" texcoord="UVMap"/></diffuse>
 </lambert></technique></profile_COMMON></effect></library_effects>
<library_materials><material id="mat" name="sign"><instance_effect url="#fx"/></material>
</library_materials>
<library_geometries><geometry id="quad"><mesh>
 <source id="pos"><float_array id="pos-a" count="12">0 -0.5 -0.25 0 0.5 -0.25 0 0.5 0.25
   0 -0.5 0.25</float_array><technique_common><accessor source="#pos-a" count="4" stride="3">
   <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
   </accessor></technique_common></source>
 <source id="uv"><float_array id="uv-a" count="8">0 0 1 0 1 1 0 1</float_array>
   <technique_common><accessor source="#uv-a" count="4" stride="2"><param name="S" type="float"/>
   <param name="T" type="float"/></accessor></technique_common></source>
 <vertices id="vtx"><input semantic="POSITION" source="#pos"/></vertices>
 <triangles count="2" material="m"><input semantic="VERTEX" source="#vtx" offset="0"/>
   <input semantic="TEXCOORD" source="#uv" offset="1" set="0"/><p>0 0 1 1 2 2 0 0 2 2 3 3</p>
 </triangles></mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#quad">
 <bind_material><technique_common><instance_material symbol="m" target="#mat"/>
 </technique_common></bind_material></instance_geometry></node></visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def test_collada_texture_is_drawn_by_the_files_uv_coordinates(tmp_path):
    from fleetsim.sim.meshes import collada_parts

    quadrant_model(tmp_path)  # writes quad.png
    (tmp_path / "sign.dae").write_text(SIGN_DAE)
    (part,) = collada_parts(tmp_path / "sign.dae")
    assert part.image == str(tmp_path / "quad.png") and part.rgba == (1.0, 1.0, 1.0, 1.0)
    # COLLADA's v grows upwards; stored with v = 0 at the image's top
    np.testing.assert_allclose(part.texcoords, [[0, 1], [1, 1], [1, 0], [0, 0]])
    assert part.texcoord_faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    sdf = f"""<sdf version="1.6"><model name="sign"><static>true</static><link name="link">
      <visual name="v"><geometry><mesh><uri>{tmp_path}/sign.dae</uri></mesh></geometry></visual>
      </link></model></sdf>"""
    e = Engine(None)
    e.spawn_sdf("sign", load_sdf_model(sdf), (0, 0, 1.0, 0, 0, 0))
    img = render_from(e, (0, 0, 1.0), 180.0, 1.2)  # from +x
    Image.fromarray(img).save(tmp_path / "dae_sign.png")
    assert_no_mujoco_warnings(e)
    h, w = img.shape[:2]
    px = h / (2 * 1.2 * np.tan(np.radians(e.model.vis.global_.fovy) / 2))
    cy, cx = h // 2, w // 2
    dy, dx = round(0.125 * px), round(0.25 * px)
    top_left, top_right = img[cy - dy, cx - dx], img[cy - dy, cx + dx]
    bottom_left, bottom_right = img[cy + dy, cx - dx], img[cy + dy, cx + dx]
    assert np.argmax(top_left) == 0 and np.argmax(top_right) == 1  # red, green
    assert np.argmax(bottom_left) == 2 and np.ptp(bottom_right) < 60  # blue, white


def test_cylinder_and_sphere_carry_gazebos_texture_coordinates():
    from fleetsim.sim.textures import cylinder_uv_mesh, sphere_uv_mesh

    for v, f, t, tf in (cylinder_uv_mesh(0.2, 1.0), sphere_uv_mesh(0.3)):
        a, b, c = (v[f[:, i]] for i in range(3))
        outward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c)
        assert np.all(outward > 0) and f.shape == tf.shape
        assert t.min() >= 0 and t.max() <= 1
    v, f, t, tf = cylinder_uv_mesh(0.2, 1.0)
    side = np.abs(v[f[:, 0], 2] - v[f[:, 1], 2]) + np.abs(v[f[:, 1], 2] - v[f[:, 2], 2]) > 0
    corners, uv = v[f[side]].reshape(-1, 3), t[tf[side]].reshape(-1, 2)
    # u follows the angle from +y towards +x (Gazebo's x = r sin, y = r cos); v = 0 at the bottom
    angle = np.mod(np.arctan2(corners[:, 0], corners[:, 1]), 2 * np.pi)
    seam = uv[:, 0] == 1.0
    np.testing.assert_allclose(np.where(seam, 2 * np.pi, angle), uv[:, 0] * 2 * np.pi, atol=1e-9)
    np.testing.assert_allclose(uv[:, 1], (corners[:, 2] + 0.5) / 1.0)
    v, f, t, tf = sphere_uv_mesh(0.3)
    corners, uv = v[f].reshape(-1, 3), t[tf].reshape(-1, 2)
    np.testing.assert_allclose(uv[:, 1], np.arccos(np.clip(corners[:, 1] / 0.3, -1, 1)) / np.pi)


def test_textured_cylinder_and_sphere_show_the_image(tmp_path):
    quadrant_model(tmp_path)
    sdf = """<sdf version="1.6"><model name="shapes"><static>true</static><link name="link">
      <visual name="c"><pose>0 -0.4 0 0 0 0</pose><geometry><cylinder><radius>0.2</radius>
        <length>0.6</length></cylinder></geometry>{mat}</visual>
      <visual name="s"><pose>0 0.4 0 0 0 0</pose><geometry><sphere><radius>0.25</radius>
        </sphere></geometry>{mat}</visual></link></model></sdf>"""
    mat = (
        f"<material><script><uri>file://{tmp_path}</uri><name>Sign/Quadrants</name></script>"
        "</material>"
    )
    e = Engine(None)
    e.spawn_sdf("shapes", load_sdf_model(sdf.format(mat=mat)), (0, 0, 1.0, 0, 0, 0))
    img = render_from(e, (0, 0, 1.0), 180.0, 1.6, (320, 240))
    Image.fromarray(img).save(tmp_path / "shapes.png")
    assert_no_mujoco_warnings(e)
    for half in (img[:, :160], img[:, 160:]):  # the cylinder (left of the view), the sphere
        px = half.reshape(-1, 3).astype(int)
        shown = {
            "red": np.any((px[:, 0] > 150) & (px[:, 1] < 60) & (px[:, 2] < 60)),
            "green": np.any((px[:, 1] > 150) & (px[:, 0] < 60) & (px[:, 2] < 60)),
            "blue": np.any((px[:, 2] > 150) & (px[:, 0] < 60) & (px[:, 1] < 60)),
        }
        assert sum(shown.values()) >= 2, shown  # the image's colours, not their mean
