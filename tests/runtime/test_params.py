"""Parameter declarations, validation and the rosparam-style tree."""

import logging
from dataclasses import dataclass

import pytest

from fleetsim.errors import ParameterError
from fleetsim.runtime import ParamTree, describe_params, load_params, param


@dataclass(frozen=True)
class PlannerParams:
    max_vel_x: float = param(0.5, unit="m/s", range=(0.0, None), help="top forward speed")
    max_vel_theta: float = param(
        1.0, unit="rad/s", aliases=("max_rotational_vel",), help="top turn rate"
    )
    vx_samples: int = param(3, range=(1, None), help="forward velocity samples")
    holonomic_robot: bool = param(True, help="strafe allowed")
    odom_model_type: str = param("diff", choices=("diff", "omni"), help="motion model")
    footprint: list[list[float]] = param([], unit="m", help="polygon")
    laser_max_range: float | None = param(None, unit="m", help="None: the scan's own")


def test_defaults_are_declared_once():
    p = load_params(PlannerParams, {})
    assert p.max_vel_x == 0.5 and p.vx_samples == 3 and p.footprint == []
    info = {i.name: i for i in describe_params(PlannerParams)}
    assert info["max_vel_x"].unit == "m/s"
    assert info["max_vel_theta"].aliases == ("max_rotational_vel",)


def test_int_is_accepted_for_float_and_values_convert():
    p = load_params(PlannerParams, {"max_vel_x": 1, "footprint": [[1, 2], [3, 4]]})
    assert p.max_vel_x == 1.0 and isinstance(p.max_vel_x, float)
    assert p.footprint == [[1.0, 2.0], [3.0, 4.0]]


@pytest.mark.parametrize(
    ("values", "match"),
    [
        (
            {"max_vel_x": "fast"},
            r"/ns/planner: parameter 'max_vel_x' must be float, got str 'fast'",
        ),
        ({"vx_samples": 2.5}, r"'vx_samples' must be int, got float 2.5"),
        ({"holonomic_robot": 1}, r"'holonomic_robot' must be bool"),
        ({"max_vel_x": -1.0}, r"'max_vel_x' = -1.0 is out of range \[0, inf\] m/s"),
        ({"vx_samples": 0}, r"'vx_samples' = 0 is out of range \[1, inf\]"),
        ({"odom_model_type": "dif"}, r"must be one of 'diff', 'omni'.*did you mean 'diff'"),
        ({"max_vel_x": float("nan")}, r"'max_vel_x' is NaN"),
    ],
)
def test_bad_values_name_the_parameter(values, match):
    with pytest.raises(ParameterError, match=match):
        load_params(PlannerParams, values, where="/ns/planner")


def test_old_names_work_with_a_warning(caplog):
    with caplog.at_level(logging.WARNING):
        p = load_params(PlannerParams, {"max_rotational_vel": 2.0}, where="x.yaml")
    assert p.max_vel_theta == 2.0
    assert "'max_rotational_vel' is deprecated, use 'max_vel_theta'" in caplog.text


def test_unknown_keys_are_warned_with_a_suggestion(caplog):
    with caplog.at_level(logging.WARNING):
        load_params(PlannerParams, {"max_vel_xx": 1.0, "TrajectoryPlannerROS": {}}, where="f")
    assert "unknown parameter 'max_vel_xx' (did you mean 'max_vel_x'?)" in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        load_params(PlannerParams, {"TrajectoryPlannerROS": {}}, ignore=("TrajectoryPlannerROS",))
    assert caplog.text == ""


def test_optional_accepts_none_and_value():
    assert load_params(PlannerParams, {"laser_max_range": 12}).laser_max_range == 12.0
    assert load_params(PlannerParams, {"laser_max_range": None}).laser_max_range is None


def test_tree_get_set_and_namespaces():
    t = ParamTree()
    t.set("/lizi1/amcl/min_particles", 500)
    assert t.get("/lizi1/amcl/min_particles") == 500
    assert t.get("/lizi1/amcl") == {"min_particles": 500}
    assert t.get("/nope", 3) == 3
    with pytest.raises(ParameterError, match="'/nope' is not set"):
        t.get("/nope")
    t.set("/lizi1/amcl", {"max_particles": 10})  # a dict replaces
    assert t.get("/lizi1/amcl") == {"max_particles": 10}
    assert t.names() == ["/lizi1/amcl/max_particles"]
    t.delete("/lizi1/amcl/max_particles")
    assert not t.has("/lizi1/amcl/max_particles")


def test_load_merges_leaf_by_leaf(tmp_path):
    # costmap_common_params loaded into both costmaps, then each costmap's own file
    common = tmp_path / "costmap_common_params.yaml"
    common.write_text("obstacle_range: 2.5\nrobot_radius: 0.2\n")
    glob = tmp_path / "global_costmap_params.yaml"
    glob.write_text("global_costmap:\n  global_frame: /map\n  static_map: true\n")
    t = ParamTree()
    t.load_file(common, "/lizi1/move_base/global_costmap")
    t.load_file(glob, "/lizi1/move_base")
    assert t.get("/lizi1/move_base/global_costmap") == {
        "obstacle_range": 2.5,
        "robot_radius": 0.2,
        "global_frame": "/map",
        "static_map": True,
    }


def test_yaml_errors_name_file_and_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("a: 1\nb: [1, 2\nc: 3\n")
    with pytest.raises(ParameterError, match=r"bad.yaml:\d+:\d+: YAML does not parse"):
        ParamTree().load_file(bad, "/")
    lst = tmp_path / "list.yaml"
    lst.write_text("- 1\n- 2\n")
    with pytest.raises(ParameterError, match=r"list.yaml: .*mapping at the top level, got list"):
        ParamTree().load_file(lst, "/")
    with pytest.raises(ParameterError, match="cannot read parameter file"):
        ParamTree().load_file(tmp_path / "missing.yaml", "/")


def test_search_walks_up_from_the_private_namespace():
    t = ParamTree()
    t.set("/lizi1/tf_prefix", "lizi1")
    t.set("/tf_prefix", "top")
    assert t.search("tf_prefix", "/lizi1/move_base") == "/lizi1/tf_prefix"
    assert t.search("tf_prefix", "/other/node") == "/tf_prefix"
    assert ParamTree().search("tf_prefix", "/a/b") is None
