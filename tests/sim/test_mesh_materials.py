"""COLLADA materials: one coloured part per material, and their use for visual meshes."""

import warnings

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim import Engine
from fleetsim.sim.build import add_sdf_model, new_world_spec
from fleetsim.sim.meshes import (
    NEUTRAL_GREY,
    clear_mesh_cache,
    collada_parts,
    triangle_mesh_from_collada,
)

from .test_meshes import CUBE, TRIS, VTX, collada, mesh_model, write

# --- materials: one coloured part per material ------------------------------------------------

TOP_BOTTOM, SIDES = " ".join(TRIS.split()[:12]), " ".join(TRIS.split()[12:])


def material_collada(lids="red", sides="blue", effects="", bind=("red", "blue"), extra=""):
    """The cube with its bottom and top (4 triangles) in material ``lids`` and its sides (8) in
    ``sides``; ``effects`` maps material id to the effect's ``<phong>`` body; ``bind`` lists the
    materials bound in the scene (a symbol is the material id)."""
    prims = (
        f'<triangles count="4" material="{lids}">{VTX}<p>{TOP_BOTTOM}</p></triangles>'
        f'<triangles count="8" material="{sides}">{VTX}<p>{SIDES}</p></triangles>'
    )
    inst = "".join(f'<instance_material symbol="{m}" target="#{m}"/>' for m in bind)
    nodes = (
        '<node id="n"><instance_geometry url="#cube"><bind_material><technique_common>'
        f"{inst}</technique_common></bind_material></instance_geometry></node>"
    )
    libs = (
        "<library_effects>"
        + "".join(
            f'<effect id="{m}-fx"><profile_COMMON><technique sid="c"><phong>{body}</phong>'
            "</technique></profile_COMMON></effect>"
            for m, body in effects.items()
        )
        + "</library_effects><library_materials>"
        + "".join(
            f'<material id="{m}" name="{m}-name"><instance_effect url="#{m}-fx"/></material>'
            for m in effects
        )
        + "</library_materials>"
    )
    text = collada(prims=prims, nodes=nodes)
    return text.replace("<library_geometries>", extra + libs + "<library_geometries>")


def diffuse(r, g, b, rest=""):
    return f"<diffuse><color>{r} {g} {b} 1</color></diffuse>{rest}"


RED_BLUE = {"red": diffuse(0.9, 0.1, 0.1), "blue": diffuse(0.1, 0.2, 0.9)}


def test_two_materials_give_two_coloured_parts(tmp_path):
    path = write(tmp_path, material_collada(effects=RED_BLUE))
    parts = collada_parts(path)
    assert [p.name for p in parts] == ["red-name", "blue-name"]
    assert [p.faces.shape for p in parts] == [(4, 3), (8, 3)]
    assert parts[0].rgba == pytest.approx((0.9, 0.1, 0.1, 1.0))
    assert parts[1].rgba == pytest.approx((0.1, 0.2, 0.9, 1.0))
    assert len(parts[0].vertices) == 8 and not parts[0].faces.flags.writeable
    # together the parts hold exactly the file's triangles
    v, f = triangle_mesh_from_collada(path)
    whole = sorted(map(tuple, v[f].reshape(-1, 9).round(6)))
    joined = sorted(
        t for p in parts for t in map(tuple, p.vertices[p.faces].reshape(-1, 9).round(6))
    )
    assert whole == joined
    assert collada_parts(path) is parts  # cached


@pytest.mark.parametrize(
    ("body", "rgba"),
    [  # A_ONE: alpha x transparency; RGB_ZERO: 1 - luminance x transparency; lone: ignored
        (diffuse(2, 0.5, -1, '<transparent><color>0 0 0 0.5</color></transparent>'
                 "<transparency><float>0.8</float></transparency>"), (1, 0.5, 0, 0.4)),
        (diffuse(0, 1, 0, '<transparent opaque="RGB_ZERO"><color>1 1 1 1</color></transparent>'
                 "<transparency><float>0.25</float></transparency>"), (0, 1, 0, 0.75)),
        (diffuse(0, 1, 0, '<transparent opaque="RGB_ZERO"><color>1 1 1 1</color></transparent>'),
         (0, 1, 0, 0.0)),
        (diffuse(0, 1, 0, "<transparency><float>0</float></transparency>"), (0, 1, 0, 1)),
    ],
    ids=["a_one", "rgb_zero", "rgb_zero_default", "lone_transparency"],
)  # fmt: skip
def test_material_alpha_and_clipping(tmp_path, body, rgba):
    effects = {"red": body, "blue": diffuse(0, 0, 1)}
    parts = collada_parts(write(tmp_path, material_collada(effects=effects)))
    assert parts[0].rgba == pytest.approx(rgba)


def test_unbound_and_symbol_named_materials(tmp_path):
    # 'blue' is not bound in the scene but names a material: Gazebo's fallback uses it;
    # 'nothing' names no material: grey, unnamed
    text = material_collada(sides="nothing", effects=RED_BLUE, bind=("red",))
    parts = collada_parts(write(tmp_path, text, "a.dae"))
    assert [(p.name, p.rgba) for p in parts] == [
        ("red-name", pytest.approx((0.9, 0.1, 0.1, 1))),
        ("", NEUTRAL_GREY),
    ]
    text = material_collada(effects=RED_BLUE, bind=("red",))
    assert collada_parts(write(tmp_path, text, "b.dae"))[1].rgba == pytest.approx(
        (0.1, 0.2, 0.9, 1)
    )


def textured(image):
    return (
        '<newparam sid="surf"><surface type="2D"><init_from>img</init_from></surface></newparam>'
        '<newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>',
        f'<library_images><image id="img"><init_from>{image}</init_from></image></library_images>',
    )


def test_texture_diffuse_takes_the_image_mean_colour_or_grey(tmp_path):
    from PIL import Image

    params, images = textured("tex%20one.png")  # URL-encoded, as exporters write spaces
    text = material_collada(effects=RED_BLUE, extra=images).replace(
        '<profile_COMMON><technique sid="c"><phong><diffuse><color>0.9 0.1 0.1 1</color>',
        f'<profile_COMMON>{params}<technique sid="c"><phong>'
        '<diffuse><texture texture="samp" texcoord="UV"/>',
    )
    (tmp_path / "model" / "meshes").mkdir(parents=True)
    dae = write(tmp_path / "model" / "meshes", text)
    with pytest.warns(UserWarning, match=r"m\.dae': texture image 'tex%20one\.png' of material "
                      r"'red-name' is not found.*neutral grey"):  # fmt: skip
        assert collada_parts(dae)[0].rgba == NEUTRAL_GREY
    pixels = np.zeros((4, 8, 3), np.uint8)
    pixels[:, :4] = (255, 0, 0)
    pixels[:, 4:] = (0, 0, 255)
    textures = tmp_path / "model" / "materials" / "textures"  # Gazebo's model layout
    textures.mkdir(parents=True)
    Image.fromarray(pixels).save(textures / "tex one.png")
    clear_mesh_cache()
    assert collada_parts(dae)[0].rgba == pytest.approx((0.5, 0, 0.5, 1), abs=0.02)


def robot_urdf(tmp_path, dae, material="", collision_mesh=False):
    collision = (  # resting on the ground
        f'<origin xyz="0 0 0.25"/><geometry><mesh filename="{dae}" scale="0.5 0.5 0.5"/>'
        if collision_mesh
        else '<origin xyz="0 0 0.1"/><geometry><box size="0.2 0.2 0.2"/>'
    )
    urdf = f"""<robot name="paintbot"><link name="base_link">
        <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0"
          izz="0.01"/></inertial>
        <collision>{collision}</geometry></collision>
        <visual name="body"><origin xyz="0 0 0.25"/><geometry>
          <mesh filename="{dae}" scale="0.5 0.5 0.5"/></geometry>{material}</visual>
      </link></robot>"""
    return write(tmp_path, urdf, "paintbot.urdf")


def mesh_geoms(m):
    return [g for g in range(m.ngeom) if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]


def test_visual_dae_robot_renders_its_material_colours(tmp_path):
    dae = write(tmp_path, material_collada(effects=RED_BLUE), "paint.dae")
    e = Engine(None)
    e.spawn_robot("p1", robot_urdf(tmp_path, dae), (0, 0, 0, 0, 0, 0))
    e.spawn_robot("p2", robot_urdf(tmp_path, dae), (3, 0, 0, 0, 0, 0))
    m = e.model
    geoms = mesh_geoms(m)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in geoms]
    assert names == [f"{r}/base_link/body#1:{k}" for r in ("p1", "p2") for k in (0, 1)]
    assert m.nmesh == 2  # one asset per part, shared by both robots
    np.testing.assert_allclose(m.geom_rgba[geoms[:2]], [[0.9, 0.1, 0.1, 1], [0.1, 0.2, 0.9, 1]])
    assert all(m.geom_contype[g] == 0 and m.geom_group[g] == 1 for g in geoms)
    e.advance(0.05)
    np.testing.assert_allclose(e.data.geom_xpos[geoms[:2]], [[0, 0, 0.25]] * 2, atol=2e-3)
    cam = mujoco.MjvCamera()
    cam.lookat[:] = [0, 0, 0.25]
    cam.distance, cam.elevation, cam.azimuth = 1.2, -35.0, 60.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        renderer = e.renderer(64, 48)
    renderer.update_scene(e.data, cam)
    img = renderer.render().astype(int)
    red = (img[..., 0] > 100) & (img[..., 1] < 60) & (img[..., 2] < 60)
    blue = (img[..., 2] > 100) & (img[..., 0] < 60) & (img[..., 1] < 90)
    assert red.mean() > 0.05 and blue.mean() > 0.1  # the top in red, the sides in blue
    e.close()


def test_explicit_colour_and_collision_keep_one_mesh(tmp_path):
    dae = write(tmp_path, material_collada(effects=RED_BLUE), "paint.dae")
    green = '<material name="g"><color rgba="0 1 0 1"/></material>'
    e = Engine(None)
    e.spawn_robot("g1", robot_urdf(tmp_path, dae, green, collision_mesh=True), (0, 0, 0, 0, 0, 0))
    m = e.model
    geoms = mesh_geoms(m)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in geoms]
    assert names == ["g1/base_link/collision#0", "g1/base_link/body#1"] and m.nmesh == 1
    np.testing.assert_allclose(m.geom_rgba[geoms[1]], [0, 1, 0, 1])
    e.close()


def test_one_triangle_and_degenerate_parts(tmp_path):
    effects = {**RED_BLUE, "flat": diffuse(0, 1, 0)}
    prims = (
        f'<triangles count="1" material="red">{VTX}<p>0 2 3</p></triangles>'
        f'<triangles count="1" material="flat">{VTX}<p>0 1 1</p></triangles>'
        f'<triangles count="8" material="blue">{VTX}<p>{SIDES}</p></triangles>'
    )
    text = material_collada(effects=effects, bind=("red", "blue", "flat"))
    text = text.replace(text[text.index('<triangles count="4"') : text.index("</mesh>")], prims)
    spec = new_world_spec()
    add_sdf_model(spec, mesh_model(write(tmp_path, text), collide=False))
    m = spec.compile()
    assert m.ngeom == 2 and list(m.mesh_facenum) == [1, 8]  # the zero-area part is left out
    np.testing.assert_allclose(m.geom_rgba, [[0.9, 0.1, 0.1, 1], [0.1, 0.2, 0.9, 1]])


@settings(max_examples=15, deadline=None)
@given(st.lists(st.sampled_from(["red", "blue", "none"]), min_size=12, max_size=12))
def test_parts_partition_the_triangles_property(tmp_path_factory, owners):
    """Any assignment of the cube's triangles to materials: one part per material in order of
    first use, each with its triangles, together exactly the file's triangles."""
    tris = np.array(TRIS.split()).reshape(12, 3)
    prims = "".join(
        f'<triangles count="1" material="{o}">{VTX}<p>{" ".join(t)}</p></triangles>'
        for o, t in zip(owners, tris)
    )
    text = material_collada(effects=RED_BLUE)
    text = text.replace(text[text.index('<triangles count="4"') : text.index("</mesh>")], prims)
    path = write(tmp_path_factory.mktemp("parts"), text)
    parts = collada_parts(path)
    names = {"red": "red-name", "blue": "blue-name", "none": ""}
    assert [p.name for p in parts] == [names[o] for o in dict.fromkeys(owners)]
    for p in parts:
        mine = [t for o, t in zip(owners, tris.astype(int)) if names[o] == p.name]
        np.testing.assert_array_equal(p.vertices[p.faces], CUBE[np.array(mine)])
