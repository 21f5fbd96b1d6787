"""Decoding of ROS image payloads: encodings, row padding, byte order, compressed depth."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from hiper_cli.errors import LogError
from hiper_cli.perceive.logs.images import (
    decode_compressed_depth,
    decode_compressed_rgb,
    decode_depth,
    decode_rgb,
)

RNG = np.random.default_rng(3)
RGB = RNG.integers(0, 256, size=(4, 5, 3), dtype=np.uint8)


def padded(rows: np.ndarray, pad: int) -> tuple[np.ndarray, int]:
    flat = rows.reshape(rows.shape[0], -1).view(np.uint8)
    out = np.concatenate([flat, np.zeros((rows.shape[0], pad), dtype=np.uint8)], axis=1)
    return out.reshape(-1), out.shape[1]


def test_rgb8_bgr8_mono8_with_row_padding():
    data, step = padded(RGB, 3)
    np.testing.assert_array_equal(decode_rgb("rgb8", 4, 5, step, data, False, "t"), RGB)
    data, step = padded(np.ascontiguousarray(RGB[:, :, ::-1]), 0)
    np.testing.assert_array_equal(decode_rgb("bgr8", 4, 5, step, data, False, "t"), RGB)
    grey = RGB[:, :, 0].copy()
    out = decode_rgb("mono8", 4, 5, 5, grey.reshape(-1), False, "t")
    np.testing.assert_array_equal(out[:, :, 2], grey)


def test_depth_encodings():
    mm = RNG.integers(0, 5000, size=(4, 5)).astype(np.uint16)
    little = decode_depth("16UC1", 4, 5, 10, mm.astype("<u2").view(np.uint8).reshape(-1), False, "t")
    big = decode_depth("mono16", 4, 5, 10, mm.astype(">u2").view(np.uint8).reshape(-1), True, "t")
    np.testing.assert_allclose(little, mm / 1000.0, atol=1e-6)
    np.testing.assert_array_equal(little, big)
    metres = (mm / 1000.0).astype(np.float32)
    metres[0, 0] = np.nan
    out = decode_depth("32FC1", 4, 5, 20, metres.view(np.uint8).reshape(-1), False, "t")
    assert out.dtype == np.float32 and out[0, 0] == 0.0
    np.testing.assert_array_equal(out[1:], metres[1:])


def test_bad_payloads():
    with pytest.raises(LogError, match=r"cam #3: unknown colour encoding 'yuv422'"):
        decode_rgb("yuv422", 4, 5, 10, np.zeros(40, np.uint8), False, "cam #3")
    with pytest.raises(LogError, match=r"unknown depth encoding '8UC1'"):
        decode_depth("8UC1", 4, 5, 5, np.zeros(20, np.uint8), False, "d")
    with pytest.raises(LogError, match=r"the message is truncated"):
        decode_rgb("rgb8", 4, 5, 15, np.zeros(20, np.uint8), False, "c")


def test_compressed_images():
    ok, png = cv2.imencode(".png", RGB[:, :, ::-1])
    assert ok
    np.testing.assert_array_equal(decode_compressed_rgb("png", png.reshape(-1), "c"), RGB)
    mm = RNG.integers(1, 5000, size=(4, 5)).astype(np.uint16)
    ok, png16 = cv2.imencode(".png", mm)
    header = np.zeros(12, dtype=np.uint8)  # compressed_depth_image_transport's config header
    payload = np.concatenate([header, png16.reshape(-1)])
    out = decode_compressed_depth("16UC1; compressedDepth png", payload, "d")
    np.testing.assert_allclose(out, mm / 1000.0, atol=1e-6)
    with pytest.raises(LogError, match=r"cannot decode the compressed image"):
        decode_compressed_rgb("jpeg", np.frombuffer(b"nope", np.uint8), "c")
