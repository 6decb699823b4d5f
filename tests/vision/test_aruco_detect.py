from __future__ import annotations

import cv2
import numpy as np
import pytest
from marker_images import camera_info_msg, camera_matrix, image_msg, marker_image
from scipy.spatial.transform import Rotation

from fleetsim.errors import ParameterError
from fleetsim.msgs import fiducial_msgs, sensor_msgs, std_msgs, std_srvs, tf2_msgs
from fleetsim.runtime import Node, Runtime
from fleetsim.vision import ArucoDetect, VisionError, compress_image

W, H, HFOV = 640, 480, 1.3439  # the waffle's field of view
K = camera_matrix(W, H, HFOV)
FRAME = "camera_rgb_optical_frame"


class Harness:
    """aruco_detect in a runtime, fed by a test node, its outputs collected."""

    def __init__(self, params=None, remaps=None, info=True, watch_images=True):
        self.rt = Runtime()
        self.src = Node(self.rt, "camera_driver")
        self.node = ArucoDetect(self.rt, params={"dictionary": 0, **(params or {})}, remaps=remaps)
        self.image_pub = self.src.create_publisher(sensor_msgs.Image, "/camera", 1)
        self.jpeg_pub = self.src.create_publisher(
            sensor_msgs.CompressedImage, "/camera/rgb/image_raw/compressed", 1
        )
        self.info_pub = self.src.create_publisher(sensor_msgs.CameraInfo, "/camera_info", 1)
        self.vertices, self.transforms, self.tf, self.images = [], [], [], []
        self.src.create_subscription(
            fiducial_msgs.FiducialArray, "/fiducial_vertices", self.vertices.append, 0
        )
        self.src.create_subscription(
            fiducial_msgs.FiducialTransformArray, "/fiducial_transforms", self.transforms.append, 0
        )
        self.src.create_subscription(tf2_msgs.TFMessage, "/tf", self.tf.append, 0)
        if watch_images:
            self.src.create_subscription(
                sensor_msgs.Image, "/fiducial_images", self.images.append, 0
            )
        if info:
            self.send_info(camera_info_msg(K, W, H, FRAME))

    def send_info(self, msg):
        self.info_pub.publish(msg)
        self.rt.spin_once()

    def send(self, rgb, t=1.0, compressed=False):
        msg = image_msg(rgb, t, FRAME)
        if compressed:
            self.jpeg_pub.publish(compress_image(msg, quality=95))
        else:
            self.image_pub.publish(msg)
        self.rt.spin_once()


def facing(yaw_deg: float, pitch_deg: float = 0.0) -> Rotation:
    """A marker turned ``yaw_deg`` about the vertical from facing the camera."""
    return (
        Rotation.from_euler("x", 180, degrees=True)
        * Rotation.from_euler("y", yaw_deg, degrees=True)
        * Rotation.from_euler("x", pitch_deg, degrees=True)
    )


def pose_errors(ft, rot: Rotation, t: np.ndarray) -> tuple[float, float]:
    tr, q = ft.transform.translation, ft.transform.rotation
    got_t = np.array([tr.x, tr.y, tr.z])
    got_r = Rotation.from_quat([q.x, q.y, q.z, q.w])
    return float(np.linalg.norm(got_t - t)), float(np.degrees((got_r.inv() * rot).magnitude()))


@pytest.mark.parametrize("z", [1.0, 1.5, 2.0, 2.5, 3.0])
def test_pose_within_2cm_and_2deg_of_ground_truth(z):
    """The tutorial's camera (1920x1080, hfov 1.3439) and marker (0.15 m, DICT_4X4_50 id 0),
    seen from behind at an angle as the follower sees it, 1-3 m away."""
    w, h = 1920, 1080
    k = camera_matrix(w, h, HFOV)
    hn = Harness({"fiducial_len": 0.15}, info=False)
    hn.send_info(camera_info_msg(k, w, h, FRAME))
    rng = np.random.default_rng(int(z * 10))
    for yaw in (-40.0, -20.0, 15.0, 35.0):
        rot = facing(yaw, rng.uniform(-10, 10))
        t = np.array([rng.uniform(-0.25, 0.25) * z, rng.uniform(-0.1, 0.1) * z, z])
        img = marker_image(rot.as_rotvec(), t, k, w, h, noise=1.0, rng=rng)
        hn.send(img)
        (ft,) = hn.transforms[-1].transforms
        assert ft.fiducial_id == 0
        dt, da = pose_errors(ft, rot, t)
        assert dt < 0.02, f"z={z} yaw={yaw}: {dt * 100:.2f} cm"
        assert da < 2.0, f"z={z} yaw={yaw}: {da:.2f} deg"
        assert ft.image_error < 0.5 and ft.object_error < 0.005
        assert ft.fiducial_area > 0


def test_face_on_marker_position_within_2cm():
    """Face on, the marker's tilt is barely observable (4 corners, sub-pixel differences);
    its position still is."""
    w, h = 1920, 1080
    k = camera_matrix(w, h, HFOV)
    hn = Harness({"fiducial_len": 0.15}, info=False)
    hn.send_info(camera_info_msg(k, w, h, FRAME))
    for z in (1.0, 2.0, 3.0):
        t = np.array([0.1, 0.05, z])
        hn.send(marker_image(facing(0).as_rotvec(), t, k, w, h))
        dt, da = pose_errors(hn.transforms[-1].transforms[0], facing(0), t)
        assert dt < 0.02
        assert da < 6.0


def test_outputs_for_every_image_with_stamp_frame_and_seq():
    hn = Harness({"fiducial_len": 0.15})
    hn.send(np.full((H, W, 3), 120, np.uint8), t=2.5)
    t = np.array([0.0, 0.0, 1.2])
    hn.send(marker_image(facing(20).as_rotvec(), t, K, W, H), t=2.6)
    assert [len(m.fiducials) for m in hn.vertices] == [0, 1]
    assert [len(m.transforms) for m in hn.transforms] == [0, 1]
    last = hn.transforms[-1]
    assert last.header.frame_id == FRAME and last.image_seq == 2
    assert last.header.stamp.to_sec() == pytest.approx(2.6)
    f = hn.vertices[-1].fiducials[0]
    corners = np.array([[f.x0, f.y0], [f.x1, f.y1], [f.x2, f.y2], [f.x3, f.y3]])
    # OpenCV order: top-left, top-right, bottom-right, bottom-left
    assert corners[0, 0] < corners[1, 0] and corners[1, 1] < corners[2, 1]
    (tf,) = hn.tf[-1].transforms
    assert tf.header.frame_id == FRAME and tf.child_frame_id == "fiducial_0"
    assert tf.transform.translation.z == pytest.approx(1.2, abs=0.05)


def test_compressed_transport_through_the_tutorials_remap():
    hn = Harness(
        {"fiducial_len": 0.15, "image_transport": "compressed", "publish_images": True},
        remaps={"/camera/compressed": "/camera/rgb/image_raw/compressed"},
    )
    t = np.array([0.2, 0.0, 1.5])
    hn.send(marker_image(facing(25).as_rotvec(), t, K, W, H), compressed=True)
    (ft,) = hn.transforms[-1].transforms
    assert pose_errors(ft, facing(25), t)[0] < 0.05
    (img,) = hn.images
    assert (img.width, img.height, img.encoding) == (W, H, "bgr8")


def test_watching_the_drawn_images_does_not_change_detections():
    """A recorder or viewer on /fiducial_images must not change what is detected: with one,
    the grey image had been made from the colour decode (up to 14 levels from the grey
    decode), and a recorded run drove differently (8.2 s against 10.5 s to its goal)."""
    params = {"fiducial_len": 0.15, "image_transport": "compressed", "publish_images": True}
    remaps = {"/camera/compressed": "/camera/rgb/image_raw/compressed"}
    watched = Harness(params, remaps=remaps)
    unwatched = Harness(params, remaps=remaps, watch_images=False)
    seen = {id(watched): [], id(unwatched): []}  # the grey images the detector was given
    for hn in (watched, unwatched):
        process = hn.node.process

        def keep(gray, stamp, colour, process=process, into=seen[id(hn)]):
            into.append(gray.copy())
            process(gray, stamp, colour)

        hn.node.process = keep
    rng = np.random.default_rng(7)
    for k in range(6):
        rot = facing(rng.uniform(-40, 40), rng.uniform(-10, 10))
        t = np.array([rng.uniform(-0.4, 0.4), rng.uniform(-0.1, 0.1), rng.uniform(1.5, 3.5)])
        img = marker_image(rot.as_rotvec(), t, K, W, H, noise=3.0, rng=rng).astype(np.int16)
        img[..., 0] += 40  # a tinted scene: grey from the colour decode differs
        img = np.clip(img, 0, 255).astype(np.uint8)
        for hn in (watched, unwatched):
            hn.send(img, t=1.0 + k, compressed=True)
    assert len(watched.images) == 6 and not unwatched.images
    for a, b in zip(seen[id(watched)], seen[id(unwatched)], strict=True):
        assert np.array_equal(a, b)
    for a, b in zip(watched.vertices, unwatched.vertices, strict=True):
        assert a.fiducials == b.fiducials
    assert sum(len(m.fiducials) for m in watched.vertices) >= 4


def test_markers_of_another_dictionary_are_pointed_out(caplog):
    """A DICT_4X4_50 marker with ``dictionary`` 8 (DICT_6X6_50) is never detected, and ROS's
    aruco_detect says nothing; after 30 images without a marker the other dictionaries are
    tried once, and the one that holds the marker is named. Plain images are not warned of."""
    import logging

    t = np.array([0.1, 0.0, 1.5])
    img = marker_image(facing(20).as_rotvec(), t, K, W, H)
    blank = np.full((H, W, 3), 170, np.uint8)
    with caplog.at_level(logging.WARNING):
        wrong = Harness({"fiducial_len": 0.15, "dictionary": 8})
        for k in range(35):
            wrong.send(img, t=1.0 + 0.1 * k)
        quiet = Harness({"fiducial_len": 0.15})
        for k in range(35):
            quiet.send(blank, t=1.0 + 0.1 * k)
    said = [r.getMessage() for r in caplog.records if "dictionary" in r.getMessage()]
    assert len(said) == 1, said
    assert "no marker of dictionary 8 (DICT_6X6_50) in 30 images" in said[0]
    assert "markers of dictionary 0 (DICT_4X4_50), ids 0" in said[0]
    assert all(len(m.fiducials) == 0 for m in wrong.vertices)


def test_outputs_on_every_core_equal_one_threads():
    """OpenCV runs the package's 13 threshold windows as a parallel_for (its default thread
    count, one per core); markers, corners, poses and errors are a single thread's, exactly."""
    rng = np.random.default_rng(3)
    shots = [(-30.0, -0.2, 1.0), (10.0, 0.1, 1.6), (35.0, 0.3, 2.2)]
    images = [
        marker_image(facing(yaw).as_rotvec(), np.array([x, 0.05, z]), K, W, H, noise=2.0, rng=rng)
        for yaw, x, z in shots
    ]
    default = cv2.getNumThreads()
    outputs = {}
    try:
        for threads in (1, max(default, 2)):
            cv2.setNumThreads(threads)
            hn = Harness({"fiducial_len": 0.15})
            for img in images:
                hn.send(img)
            assert [len(m.transforms) for m in hn.transforms] == [1, 1, 1]
            outputs[threads] = [repr(m) for m in hn.vertices + hn.transforms + hn.tf]
    finally:
        cv2.setNumThreads(default)
    assert outputs[1] == outputs[max(default, 2)]


def test_ignore_len_override_and_no_pose_estimation():
    t = np.array([0.0, 0.0, 1.0])
    img = marker_image(facing(20).as_rotvec(), t, K, W, H)
    hn = Harness({"fiducial_len": 0.15, "ignore_fiducials": "0"})
    hn.send(img)
    assert hn.vertices[-1].fiducials == [] and hn.transforms[-1].transforms == []
    hn.src.create_publisher(std_msgs.String, "/ignore_fiducials", 1).publish(std_msgs.String("3-5"))
    hn.rt.spin_once()
    hn.send(img)
    assert len(hn.transforms[-1].transforms) == 1
    # a marker declared twice as big is estimated twice as far away
    hn2 = Harness({"fiducial_len": 0.15, "fiducial_len_override": "0: 0.3, 7-9: 0.1"})
    hn2.send(img)
    assert hn2.transforms[-1].transforms[0].transform.translation.z == pytest.approx(2.0, abs=0.05)
    hn3 = Harness({"do_pose_estimation": False, "publish_fiducial_tf": True})
    hn3.send(img)
    assert len(hn3.vertices[-1].fiducials) == 1
    assert hn3.transforms[-1].transforms == [] and hn3.tf == []


def test_enable_detections_service():
    hn = Harness()
    client = hn.src.create_client(std_srvs.SetBool, "/enable_detections")
    resp = client.call(std_srvs.SetBool.Request(data=False))
    assert resp.success and resp.message == "Disabled aruco detections."
    hn.send(np.zeros((H, W, 3), np.uint8))
    assert hn.vertices == []
    client.call(std_srvs.SetBool.Request(data=True))
    hn.send(np.zeros((H, W, 3), np.uint8))
    assert len(hn.vertices) == 1


def test_no_camera_info_no_transforms_and_one_error(caplog):
    hn = Harness(info=False)
    for _ in range(7):
        hn.send(np.zeros((H, W, 3), np.uint8))
    assert len(hn.vertices) == 7 and hn.transforms == []
    errors = [r for r in caplog.records if "No camera intrinsics" in r.getMessage()]
    assert len(errors) == 1 and "/camera_info" in errors[0].getMessage()


def test_no_camera_info_names_where_camera_info_is_published(caplog):
    """The camera's info on /camera/rgb/camera_info, the detector reading /camera_info: the
    error names where CameraInfo is published, as the missing image's warning does."""
    rt = Runtime()
    cam = Node(rt, "camera_driver")
    images = cam.create_publisher(sensor_msgs.Image, "/camera", 1)
    cam.create_publisher(sensor_msgs.CameraInfo, "/camera/rgb/camera_info", 1)
    ArucoDetect(rt, params={"dictionary": 0})
    for k in range(7):
        images.publish(image_msg(np.zeros((H, W, 3), np.uint8), 1.0 + 0.1 * k, FRAME))
        rt.spin_once()
    (error,) = [r.getMessage() for r in caplog.records if "No camera intrinsics" in r.getMessage()]
    assert "(no publisher; CameraInfo is published on /camera/rgb/camera_info)" in error


def test_no_images_at_all_are_reported_and_the_report_stops_with_the_first(caplog):
    """A detector on a robot without a camera (the tutorial's burger) or behind a remap that
    misses it never gets an image: it says so at 5 s and every 30 s, not at every tick, and
    once an image has come, never again."""
    bare = Runtime()
    ArucoDetect(bare, params={"dictionary": 0})  # nothing publishes /camera
    # a camera elsewhere is named (a typo in the remap, or another robot's camera)
    Node(bare, "cam").create_publisher(sensor_msgs.Image, "/robot2/camera/rgb/image_raw")
    with caplog.at_level("WARNING"):
        bare.run(duration=40.0)
    said = [r.getMessage() for r in caplog.records if "no image on" in r.getMessage()]
    assert len(said) == 2, said  # at 5 s and at 35 s
    assert (
        "no image on /camera for 5 s (no publisher; Image is published on "
        "/robot2/camera/rgb/image_raw): does this robot have a camera" in said[0]
    )
    assert "for 35 s" in said[1]
    caplog.clear()
    hn = Harness()  # a publisher is there: the first image ends the reports
    with caplog.at_level("WARNING"):
        hn.rt.run(duration=6.0)
        hn.send(np.zeros((H, W, 3), np.uint8))
        hn.rt.run(duration=60.0)
    said = [r.getMessage() for r in caplog.records if "no image on" in r.getMessage()]
    assert len(said) == 1 and "for 5 s" in said[0]


def test_axes_drawn_past_the_image_edge_write_nothing_to_stderr(capfd):
    """/fiducial_images with a marker at the image's edge: OpenCV's drawFrameAxes clips the
    axes, and the WARN line it writes for that (every frame) stays out of the run's output."""
    hn = Harness({"fiducial_len": 0.15, "publish_images": True})
    t = np.array([1.08, 0.0, 1.5])  # at the right edge: the x axis ends past the frame
    capfd.readouterr()
    for k in range(3):
        hn.send(marker_image(facing(0).as_rotvec(), t, K, W, H), t=1.0 + k)
    assert len(hn.images) == 3 and len(hn.transforms[-1].transforms) == 1
    err = capfd.readouterr().err
    assert "drawFrameAxes" not in err, err


def test_camera_info_with_zeros_names_the_topic():
    hn = Harness(info=False, remaps={"camera_info": "/camera/rgb/camera_info"})
    bad = camera_info_msg(np.zeros((3, 3)), W, H, FRAME)
    hn.info_pub = hn.src.create_publisher(sensor_msgs.CameraInfo, "/camera/rgb/camera_info", 1)
    with pytest.raises(VisionError, match=r"/camera/rgb/camera_info.*K is all zeros"):
        hn.send_info(bad)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"dictionary": 17}, r"parameter 'dictionary' must be one of 0, 1,.*got 17"),
        ({"dictionary": -1}, r"parameter 'dictionary'"),
        (
            {"fiducial_len_override": "50: 0.2"},
            r"'fiducial_len_override': id 50 in '50: 0.2' is not in the dictionary.*0\.\.49",
        ),
        ({"fiducial_len_override": "3-60: 0.2"}, r"'fiducial_len_override': id 60"),
        ({"fiducial_len_override": "3 0.2"}, r"'fiducial_len_override': cannot read '3 0.2'"),
        ({"fiducial_len_override": "3: -1"}, r"positive length"),
        ({"ignore_fiducials": "1,x"}, r"'ignore_fiducials': cannot read 'x'"),
        ({"ignore_fiducials": "9-2"}, r"runs backwards"),
        ({"image_transport": "theora"}, r"'image_transport' must be one of 'raw', 'compressed'"),
        ({"adaptiveThreshWinSizeMax": 2}, r"adaptiveThreshWinSizeMax"),
        ({"fiducial_len": 0.0}, r"'fiducial_len' = 0.0 is out of range"),
    ],
)
def test_bad_parameters_name_the_parameter(params, match):
    with pytest.raises(ParameterError, match=match):
        ArucoDetect(Runtime(), params={"dictionary": 0, **params})


def test_bad_images_name_the_topic():
    hn = Harness()
    msg = image_msg(np.zeros((H, W, 3), np.uint8))
    msg.encoding = "32FC1"
    hn.image_pub.publish(msg)
    with pytest.raises(VisionError, match=r"image on /camera: encoding '32FC1'"):
        hn.rt.spin_once()
    hn2 = Harness({"image_transport": "compressed"})
    pub = hn2.src.create_publisher(sensor_msgs.CompressedImage, "/camera/compressed", 1)
    pub.publish(sensor_msgs.CompressedImage(format="jpeg", data=np.arange(10, dtype=np.uint8)))
    with pytest.raises(VisionError, match=r"on /camera/compressed .* could not be decoded"):
        hn2.rt.spin_once()
