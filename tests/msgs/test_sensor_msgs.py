from __future__ import annotations

import numpy as np

from fleetsim.msgs import deserialize, sensor_msgs, serialize


def test_bulk_fields_are_typed_arrays():
    assert sensor_msgs.LaserScan().intensities.dtype == np.float32
    assert sensor_msgs.Image().data.dtype == np.uint8
    assert sensor_msgs.PointCloud2().data.dtype == np.uint8
    assert sensor_msgs.CameraInfo().k.shape == (9,)
    assert sensor_msgs.Imu().orientation_covariance.shape == (9,)
    assert sensor_msgs.JointState().name == []


def test_image_from_an_hw3_array():
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    img = sensor_msgs.Image(height=2, width=3, encoding="rgb8", step=9, data=rgb)
    back = deserialize(serialize(img), "sensor_msgs/Image")
    assert np.array_equal(back.data.reshape(2, 3, 3), rgb)
    assert img.data is rgb  # the published message was not modified


def test_point_field_constants():
    assert sensor_msgs.PointField.FLOAT32 == 7 and sensor_msgs.PointField.FLOAT64 == 8
