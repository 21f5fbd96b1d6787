import numpy as np
import pytest

from hiper_cli.errors import DataError
from hiper_cli.model import Box3D, Instance, Observation
from hiper_cli.types import CameraIntrinsics, Detections, Frame

CAM = CameraIntrinsics(width=8, height=6, fx=5.0, fy=5.0, cx=4.0, cy=3.0)


def make_frame(**overrides):
    kwargs = dict(
        stamp_s=1.0,
        rgb=np.zeros((6, 8, 3), np.uint8),
        depth_m=np.ones((6, 8), np.float32),
        camera=CAM,
        T_map_cam=np.eye(4),
        pose_id=0,
    )
    kwargs.update(overrides)
    return Frame(**kwargs)


def test_valid_frame_keeps_arrays():
    frame = make_frame()
    assert frame.width == 8 and frame.height == 6
    assert frame.T_map_cam.dtype == np.float64


def test_depth_with_wrong_dtype_names_expected_and_actual():
    with pytest.raises(DataError, match=r"depth_m expected \(H, W\) float32, got \(6, 8\) uint16"):
        make_frame(depth_m=np.ones((6, 8), np.uint16))


def test_rgb_with_wrong_shape_is_rejected():
    with pytest.raises(DataError, match=r"rgb expected \(H, W, 3\) uint8, got \(6, 8\) uint8"):
        make_frame(rgb=np.zeros((6, 8), np.uint8))


def test_nan_pose_is_rejected_with_fix():
    T = np.eye(4)
    T[0, 3] = np.nan
    with pytest.raises(DataError, match="NaN or infinite"):
        make_frame(T_map_cam=T)


def test_non_rotation_pose_is_rejected():
    T = np.eye(4)
    T[0, 0] = 2.0
    with pytest.raises(DataError, match="not a proper rotation"):
        make_frame(T_map_cam=T)


def test_image_size_must_match_intrinsics():
    with pytest.raises(DataError, match="intrinsics are for 8×6"):
        make_frame(rgb=np.zeros((4, 4, 3), np.uint8), depth_m=np.ones((4, 4), np.float32))


def test_camera_json_round_trip_and_missing_keys():
    assert CameraIntrinsics.from_dict(CAM.to_dict()) == CAM
    with pytest.raises(DataError, match=r"cam.json: missing keys \['fy'\]"):
        CameraIntrinsics.from_dict({"width": 1, "height": 1, "fx": 1, "cx": 0, "cy": 0}, "cam.json")


def test_detections_validate_counts_and_boxes():
    dets = Detections.from_records([{"xyxy": [1, 2, 3, 4], "class": "cup", "score": 0.5}])
    assert len(dets) == 1 and dets.to_records()[0]["class"] == "cup"
    assert len(Detections.empty()) == 0
    with pytest.raises(DataError, match="same count"):
        Detections(np.zeros((2, 4)), ("a",), np.zeros(2))
    with pytest.raises(DataError, match="x_max >= x_min"):
        Detections(np.array([[3.0, 0, 1, 1]]), ("a",), np.ones(1))


def test_box_transform_and_documents_round_trip():
    box = Box3D.from_points(np.array([[0, 0, 0], [2, 1, 1]], float))
    T = np.eye(4)
    T[:3, 3] = [1, 0, 0]
    moved = box.transformed(T)
    np.testing.assert_allclose(moved.center_m, [2, 0.5, 0.5])
    assert box.volume_m3 == pytest.approx(2.0)
    obs = Observation("foreground", "cup", 0.9, 1.5, 3, box, data={"image_box_xyxy": [0, 0, 1, 1]})
    assert Observation.from_dict(obs.to_dict()).to_dict() == obs.to_dict()
    inst = Instance("foreground", "cup", box, 1.0, 2.0, observation_uuids=[obs.uuid])
    assert Instance.from_dict(inst.to_dict()).to_dict() == inst.to_dict()
