"""Gazebo's pose rules: <include> overrides, radians, relative_to, nested models, frames."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from fleetsim.errors import SimulationError
from fleetsim.sim import Engine
from fleetsim.sim.mesh_files import triangle_mesh
from fleetsim.sim.sdf import load_sdf_model, load_sdf_world
from fleetsim.sim.sdf_poses import compose, inverse

from .conftest import FIXTURES


@pytest.fixture(autouse=True)
def models(monkeypatch, tmp_path):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(FIXTURES / "models"))
    monkeypatch.setenv("FLEETSIM_CACHE_DIR", str(tmp_path / "cache"))


def world(tmp_path, body: str):
    path = tmp_path / "w.world"
    path.write_text(f"<sdf version='1.7'><world name='w'>\n{body}\n</world></sdf>")
    return path


def box_model(name, pose="", links=""):
    return f"<model name='{name}'><static>true</static>{pose}{links}</model>"


def link(name, pose="", geoms=""):
    return f"<link name='{name}'>{pose}{geoms}</link>"


def collision(name, pose=""):
    return (
        f"<collision name='{name}'>{pose}<geometry><box><size>1 1 1</size></box></geometry>"
        "</collision>"
    )


def test_include_pose_is_radians_and_overrides_the_models_own(tmp_path):
    path = world(
        tmp_path,
        "<include><uri>model://mesh_building</uri><name>lesson</name>"
        "<pose>-3 54 0 0 0 30</pose></include>"
        "<include><uri>model://mesh_building</uri><name>own</name></include>",
    )
    w = load_sdf_world(path)
    lesson, own = w.models
    assert lesson.name == "lesson" and lesson.pose == (-3.0, 54.0, 0.0, 0.0, 0.0, 30.0)
    assert own.pose == (100.0, 100.0, 0.0, 0.0, 0.0, 1.0)  # the model.sdf's pose
    e = Engine(path)
    m, d = e.model, e.data
    g = m.geom("lesson/walls/collision#0:rays").id
    mid = m.geom_dataid[g]
    local = m.mesh_vert[m.mesh_vertadr[mid] : m.mesh_vertadr[mid] + m.mesh_vertnum[mid]]
    placed = local @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
    v, _ = triangle_mesh(FIXTURES / "models/mesh_building/meshes/building.obj")
    expected = v @ Rotation.from_euler("z", 30.0).as_matrix().T + (-3.0, 54.0, 0.0)
    gap = np.linalg.norm(expected[:, None] - placed[None], axis=2).min(axis=1)
    assert gap.max() < 1e-4  # every vertex where the include's pose (30 rad) puts it


def test_degrees_and_quaternion_poses(tmp_path):
    path = world(
        tmp_path,
        box_model("deg", "<pose degrees='true'>1 0 0 0 0 90</pose>")
        + box_model(
            "quat", "<pose rotation_format='quat_xyzw'>0 1 0 0 0 0.7071068 0.7071068</pose>"
        ),
    )
    deg, quat = load_sdf_world(path).models
    assert deg.pose[5] == pytest.approx(np.pi / 2) and quat.pose[5] == pytest.approx(np.pi / 2)


def test_link_and_collision_poses_relative_to_other_frames(tmp_path):
    links = (
        link("base", "<pose>1 0 0 0 0 1.5707963</pose>")
        + link("arm", "<pose relative_to='base'>1 0 0 0 0 0</pose>",
               collision("c", "<pose relative_to='tip'>0 0 0 0 0 0</pose>"))
        + "<frame name='tip' attached_to='arm'><pose>0 0 2 0 0 0</pose></frame>"
    )  # fmt: skip
    w = load_sdf_world(world(tmp_path, box_model("m", "<pose>0 0 0 0 0 0</pose>", links)))
    base, arm = w.models[0].links
    assert np.allclose(arm.pose, (1, 1, 0, 0, 0, np.pi / 2), atol=1e-6)  # 1 m along base's x
    assert np.allclose(arm.geoms[0].pose, (0, 0, 2, 0, 0, 0), atol=1e-6)  # the tip, in arm


def test_models_relative_to_other_models_and_nested_models_compose(tmp_path):
    nested = (
        "<model name='outer'><pose relative_to='anchor'>0 0 0 0 0 1.5707963</pose>"
        + link("l0", "", collision("c"))
        + "<model name='inner'><pose>2 0 0 0 0 0</pose>"
        + link("l1", "<pose>0 1 0 0 0 0</pose>", collision("c"))
        + "</model></model>"
    )
    w = load_sdf_world(world(tmp_path, box_model("anchor", "<pose>5 5 0 0 0 0</pose>") + nested))
    outer = w.models[1]
    assert np.allclose(outer.pose, (5, 5, 0, 0, 0, np.pi / 2), atol=1e-6)
    names = [lk.name for lk in outer.links]
    assert names == ["l0", "inner::l1"]
    assert np.allclose(outer.links[1].pose[:3], (2, 1, 0), atol=1e-6)


def test_placement_frame_places_the_named_link(tmp_path, monkeypatch):
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "models"))
    models = tmp_path / "models" / "thing"
    models.mkdir(parents=True)
    (models / "model.sdf").write_text(
        "<sdf version='1.8'>" + box_model("thing", "", link("foot", "<pose>0 0 -1 0 0 0</pose>"))
        + "</sdf>"
    )  # fmt: skip
    path = world(
        tmp_path,
        "<include><uri>model://thing</uri><placement_frame>foot</placement_frame>"
        "<pose>3 0 0 0 0 0</pose></include>",
    )
    m = load_sdf_world(path).models[0]
    assert np.allclose(compose(m.pose, m.links[0].pose), (3, 0, 0, 0, 0, 0), atol=1e-9)


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (box_model("m", "<pose frame='x'>0 0 0 0 0 0</pose>"), r"w.world:2: <pose frame='x'>"),
        (box_model("m", "<pose relative_to='nowhere'>0 0 0 0 0 0</pose>"),
         r"relative_to='nowhere'> of 'm' names no frame of world 'w'"),
        (box_model("m", "", link("a", "<pose relative_to='b'/>")
                   + link("b", "<pose relative_to='a'/>")),
         r"in model 'm' forms a cycle: a -> b -> a"),
        (box_model("m", "<pose rotation_format='euler_ypr'>0 0 0 0 0 0</pose>"),
         r"rotation_format='euler_ypr'> must be euler_rpy or quat_xyzw"),
        (box_model("m", "", link("a", "", collision("c", "<pose relative_to='zz'/>"))),
         r"relative_to='zz'> of collision 'c' names no frame of model 'm'"),
        ("<include><uri>model://mesh_building</uri><placement_frame>roof</placement_frame>"
         "</include>", r"<placement_frame>roof</placement_frame> names no link or frame"),
    ],
)  # fmt: skip
def test_pose_errors_name_file_and_frame(tmp_path, body, message):
    with pytest.raises(SimulationError, match=message):
        load_sdf_world(world(tmp_path, body))


def test_compose_and_inverse_are_rigid_transforms():
    rng = np.random.default_rng(3)
    for _ in range(20):
        a = (*rng.normal(size=3), *rng.uniform(-3, 3, 3))
        b = (*rng.normal(size=3), *rng.uniform(-3, 3, 3))
        ab = compose(a, b)
        m = Rotation.from_euler("xyz", a[3:]) * Rotation.from_euler("xyz", b[3:])
        assert np.allclose(Rotation.from_euler("xyz", ab[3:]).as_matrix(), m.as_matrix())
        back = compose(inverse(a), ab)
        assert np.allclose(back[:3], b[:3], atol=1e-9)
        rb = Rotation.from_euler("xyz", b[3:]).as_matrix()
        assert np.allclose(Rotation.from_euler("xyz", back[3:]).as_matrix(), rb, atol=1e-9)
    assert load_sdf_model(box_model("m", "<pose>1 2 3 0 0 0</pose>")).pose == (1, 2, 3, 0, 0, 0)


def test_model_config_picks_the_highest_sdf_version(tmp_path, monkeypatch):
    folder = tmp_path / "models" / "thing"
    folder.mkdir(parents=True)
    (folder / "model.config").write_text(
        "<model><name>thing</name><sdf version='1.4'>model-1_4.sdf</sdf>"
        "<sdf version='1.6'>model.sdf</sdf><sdf version='1.5'>model-1_5.sdf</sdf></model>"
    )
    for name, x in (("model-1_4.sdf", 4), ("model.sdf", 6), ("model-1_5.sdf", 5)):
        (folder / name).write_text(box_model("thing", f"<pose>{x} 0 0 0 0 0</pose>"))
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "models"))
    m = load_sdf_world(world(tmp_path, "<include><uri>model://thing</uri></include>")).models[0]
    assert m.pose[0] == 6.0
