"""The hunter's groups, limits and named states as move_group reads them."""

import numpy as np
import pytest

from fleetsim.errors import PlanningError

from .conftest import ARM


def test_groups_joints_and_limits(hunter_model):
    m = hunter_model
    assert m.group_names == ["arm_group", "ee"]
    assert m.active_joints("arm_group") == ARM
    assert m.end_effector_link("arm_group") == "cluedo_link"
    lim = m.limits("arm_group")
    np.testing.assert_allclose(lim.max_velocity, [0.2, 0.2, 0.2, 0.5])
    np.testing.assert_allclose(lim.max_acceleration, [1.0] * 4)  # MoveIt's default: none given
    np.testing.assert_allclose(lim.lower, [-3.14, -1.8, -1.8, -1.8])
    assert m.default_scaling() == (1.0, 1.0)


def test_named_states(hunter_model):
    names = list(hunter_model.named_targets("arm_group"))
    assert names == [
        "home", "cam_left", "cam_right", "cam_back", "cam_low", "cam_low_left",
        "cam_low_back", "cam_low_right", "home_low",
    ]  # fmt: skip
    np.testing.assert_allclose(
        hunter_model.named_target("arm_group", "home"), [-1.57, 0.1293, -0.4276, 0.3481]
    )


def test_bad_names(hunter_model):
    with pytest.raises(PlanningError, match="no planning group 'arm'; groups: arm_group, ee"):
        hunter_model.active_joints("arm")
    with pytest.raises(PlanningError, match="no named state 'hom'.*did you mean 'home'"):
        hunter_model.named_target("arm_group", "hom")
    with pytest.raises(PlanningError, match="joint 'arm_joint_02' value 2.0000 is outside"):
        hunter_model.check_within_bounds("arm_group", np.array([0, 2.0, 0, 0]))
