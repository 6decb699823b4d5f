from __future__ import annotations

import pytest

from fleetsim.msgs import deserialize, fiducial_msgs, get_type, msgs_equal, serialize

TYPES = ["Fiducial", "FiducialArray", "FiducialTransform", "FiducialTransformArray"]


def test_layouts_match_the_fiducials_package(own_def):
    assert own_def("fiducial_msgs/FiducialTransformArray") == [
        "std_msgs/Header header",
        "int32 image_seq",
        "fiducial_msgs/FiducialTransform[] transforms",
    ]
    assert own_def("fiducial_msgs/FiducialTransform") == [
        "int32 fiducial_id",
        "geometry_msgs/Transform transform",
        "float64 image_error",
        "float64 object_error",
        "float64 fiducial_area",
    ]
    assert own_def("fiducial_msgs/FiducialArray") == [
        "std_msgs/Header header",
        "int32 image_seq",
        "fiducial_msgs/Fiducial[] fiducials",
    ]
    assert own_def("fiducial_msgs/Fiducial") == [
        "int32 fiducial_id",
        "int32 direction",
        *[f"float64 {c}{i}" for i in range(4) for c in "xy"],
    ]


@pytest.mark.parametrize("name", TYPES)
def test_ros1_names_and_cdr_round_trip(name, populated):
    cls = getattr(fiducial_msgs, name)
    assert get_type(f"fiducial_msgs/{name}") is cls
    for msg in (cls(), populated(cls, seed=3)):
        back = deserialize(serialize(msg), f"fiducial_msgs/msg/{name}")
        assert msgs_equal(back, msg)


def test_identity_rotation_by_default():
    tf = fiducial_msgs.FiducialTransform()
    assert tf.transform.rotation.w == 1.0
    assert fiducial_msgs.FiducialTransformArray().transforms == []
