"""Colour artefacts of a profile: motion blur, rolling-shutter skew, misregistration, JPEG.

The camera's own image motion comes from two consecutive true poses: the image-centre point at
the frame's median depth, moved by the relative pose, gives the flow in pixels per second. The
exposure smears that flow into a line kernel; the rolling shutter shifts row r by the flow over
``(r / H - 1/2) × readout_s``; misregistration shifts the whole colour image against depth.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from hiper_cli.sensor.profiles import SensorProfile
from hiper_cli.types import CameraIntrinsics

__all__ = ["degrade_rgb", "image_flow_px_per_s", "jpeg_roundtrip"]

RgbImage = NDArray[np.uint8]
MAX_BLUR_PX = 40  # longer smears are clipped: a camera that fast gives no usable frame anyway


def image_flow_px_per_s(T_map_cam: NDArray[np.float64], T_map_cam_next: NDArray[np.float64], dt_s: float,
                        camera: CameraIntrinsics, depth_m: NDArray[np.float32]) -> NDArray[np.float64]:
    """(du, dv) pixels per second of the image centre as the camera moves between the two poses."""
    if dt_s <= 0:
        return np.zeros(2)
    valid = depth_m[depth_m > 0]
    z = float(np.median(valid)) if valid.size else 2.0
    point_cam = np.array([0.0, 0.0, z, 1.0])
    T_next_cam = np.linalg.inv(T_map_cam_next) @ T_map_cam
    moved = T_next_cam @ point_cam
    if moved[2] <= 1e-3:
        return np.zeros(2)
    du = camera.fx * moved[0] / moved[2]
    dv = camera.fy * moved[1] / moved[2]
    return np.array([du, dv]) / dt_s


def _motion_blur(rgb: RgbImage, smear_px: NDArray[np.float64]) -> RgbImage:
    import cv2

    length = float(np.hypot(*smear_px))
    if length < 0.5:
        return rgb
    if length > MAX_BLUR_PX:
        smear_px = smear_px * (MAX_BLUR_PX / length)
    half = int(np.ceil(max(abs(smear_px[0]), abs(smear_px[1])) / 2)) + 1
    kernel = np.zeros((2 * half + 1, 2 * half + 1), dtype=np.float32)
    steps = max(2, int(np.ceil(length * 2)))
    for s in np.linspace(-0.5, 0.5, steps):
        x, y = half + s * smear_px[0], half + s * smear_px[1]
        kernel[round(y), round(x)] += 1.0
    kernel /= kernel.sum()
    return np.asarray(cv2.filter2D(rgb, -1, kernel, borderType=cv2.BORDER_REPLICATE), dtype=np.uint8)


def _shift_and_skew(rgb: RgbImage, shift_px: tuple[float, float], skew_px: NDArray[np.float64]) -> RgbImage:
    """Content moved by ``shift_px`` plus, per row, ``skew_px`` × (r / H − 1/2)."""
    import cv2

    h, w = rgb.shape[:2]
    if shift_px == (0.0, 0.0) and not np.any(skew_px):
        return rgb
    rows = (np.arange(h, dtype=np.float32) / h - 0.5)[:, None]
    map_x = np.arange(w, dtype=np.float32)[None, :] - shift_px[0] - rows * float(skew_px[0])
    map_y = np.arange(h, dtype=np.float32)[:, None] - shift_px[1] - rows * float(skew_px[1])
    map_x, map_y = np.broadcast_to(map_x, (h, w)), np.broadcast_to(map_y, (h, w))
    return np.asarray(cv2.remap(rgb, np.ascontiguousarray(map_x), np.ascontiguousarray(map_y),
                                cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE), dtype=np.uint8)


def jpeg_roundtrip(rgb: RgbImage, quality: int) -> RgbImage:
    """``rgb`` encoded as JPEG at ``quality`` and decoded again."""
    import cv2

    bgr = np.ascontiguousarray(rgb[:, :, ::-1])
    ok, data = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, quality])
    decoded = cv2.imdecode(data, cv2.IMREAD_COLOR) if ok else None
    if decoded is None:
        return rgb
    return np.ascontiguousarray(np.asarray(decoded, dtype=np.uint8)[:, :, ::-1])


def degrade_rgb(rgb: RgbImage, flow_px_per_s: NDArray[np.float64], profile: SensorProfile, *,
                jpeg: bool = True) -> RgbImage:
    """The colour image ``profile``'s camera would give while its image moves at ``flow_px_per_s``.

    ``jpeg=False`` leaves the compression to the writer (a TUM folder of .jpg files).
    """
    out = _motion_blur(rgb, flow_px_per_s * profile.exposure_s) if profile.exposure_s > 0 else rgb
    out = _shift_and_skew(out, profile.misregistration_px, flow_px_per_s * profile.readout_s)
    if jpeg and profile.jpeg_quality > 0:
        out = jpeg_roundtrip(out, profile.jpeg_quality)
    return out
