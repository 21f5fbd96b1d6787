"""Depth artefacts of a profile: axial noise, disparity steps, shadows, flying pixels, dropouts.

All maps are computed on the input (ideal) depth image, in its own pixels: a projector or
second imager ``baseline_m`` along the camera's +x axis sees the point of pixel u at column
``u - fx b / z``; a pixel is in shadow when a pixel to its right reaches that column first
(a nearer surface hides the point from the projector), so shadows lie left of near objects and
are ``fx b (1/z_near - 1/z_far)`` pixels wide.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.sensor.profiles import SensorProfile
from hiper_cli.types import CameraIntrinsics

__all__ = ["axial_sigma_m", "degrade_depth", "depth_edges", "error_std_m", "grazing_dropout",
           "incidence_deg", "projector_shadow", "quantisation_step_m"]

FloatImage = NDArray[np.float32]
BoolImage = NDArray[np.bool_]
NORMAL_STEP_PX = 3
MAX_NOISE_INCIDENCE_DEG = 89.0  # the incidence term grows without bound towards 90°


def axial_sigma_m(profile: SensorProfile, z_m: NDArray[np.floating],
                  incidence: NDArray[np.floating] | None = None) -> NDArray[np.float64]:
    """Gaussian depth noise σ (m) at range ``z_m`` and ``incidence`` (deg), before quantisation.

    The incidence term is Nguyen's (and Fankhauser's) ``noise_angle_m z^p θ² / (π/2 − θ)²``.
    """
    z = np.asarray(z_m, dtype=np.float64)
    sigma = np.maximum(profile.noise_c0_m + profile.noise_c1 * z + profile.noise_c2_per_m * z * z, 0.0)
    if incidence is not None and profile.noise_angle_m > 0:
        theta = np.radians(np.clip(np.asarray(incidence, dtype=np.float64), 0.0, MAX_NOISE_INCIDENCE_DEG))
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(z > 0, np.power(np.where(z > 0, z, 1.0), profile.noise_angle_z_power), 0.0)
        sigma = sigma + profile.noise_angle_m * scale * theta**2 / (np.pi / 2 - theta) ** 2
    if profile.disparity_sigma_px > 0 and profile.disparity_focal_px > 0 and profile.baseline_m > 0:
        fb = profile.disparity_focal_px * profile.baseline_m
        from_disparity = profile.disparity_sigma_px * z * z / fb
        sigma = np.hypot(sigma, from_disparity)
    return sigma


def quantisation_step_m(profile: SensorProfile, z_m: NDArray[np.floating]) -> NDArray[np.float64]:
    """Depth step (m) of one disparity quantum at ``z_m``: z² step / (f b); 0 without quantisation."""
    z = np.asarray(z_m, dtype=np.float64)
    if not profile.quantised:
        return np.zeros_like(z)
    return z * z * profile.disparity_step_px / (profile.disparity_focal_px * profile.baseline_m)


def error_std_m(profile: SensorProfile, z_m: NDArray[np.floating],
                incidence: NDArray[np.floating] | None = None) -> NDArray[np.float64]:
    """The documented model of the added depth error: √(σ_z² + step²/12) (noise, then quantisation)."""
    step = quantisation_step_m(profile, z_m)
    return np.sqrt(axial_sigma_m(profile, z_m, incidence) ** 2 + step * step / 12.0)


def projector_shadow(depth_m: FloatImage, fx: float, baseline_m: float) -> BoolImage:
    """Pixels the projector (``baseline_m`` along +x) cannot light: hidden by a nearer surface."""
    w = depth_m.shape[1]
    valid = depth_m > 0
    cols = np.arange(w, dtype=np.float64)[None, :]
    with np.errstate(divide="ignore"):
        x_proj = np.where(valid, cols - fx * baseline_m / np.where(valid, depth_m, 1.0), np.inf)
    # smallest projector column among the pixels to the right of each pixel
    suffix_min = np.minimum.accumulate(x_proj[:, ::-1], axis=1)[:, ::-1]
    right_min = np.full_like(x_proj, np.inf)
    right_min[:, :-1] = suffix_min[:, 1:]
    return valid & (x_proj > right_min)


def _neighbours(depth_m: FloatImage) -> NDArray[np.float32]:
    """(4, H, W) depth of the left, right, upper and lower neighbour (edge-replicated)."""
    padded = np.pad(depth_m, 1, mode="edge")
    return np.stack([padded[1:-1, :-2], padded[1:-1, 2:], padded[:-2, 1:-1], padded[2:, 1:-1]])


def depth_edges(depth_m: FloatImage, jump_frac: float) -> tuple[BoolImage, FloatImage]:
    """Pixels next to a depth step larger than ``jump_frac`` × their depth, and the depth across it.

    Returns (edge mask, the valid 4-neighbour depth farthest from the pixel's own).
    """
    nbrs = _neighbours(depth_m)
    valid = (nbrs > 0) & (depth_m > 0)[None]
    diff = np.where(valid, np.abs(nbrs - depth_m[None]), 0.0)
    far = np.argmax(diff, axis=0)
    across = np.take_along_axis(nbrs, far[None], axis=0)[0]
    edge = diff.max(axis=0) > jump_frac * depth_m
    return edge & (depth_m > 0), across.astype(np.float32)


def _smaller_step(points: NDArray[np.float64], depth_m: NDArray[np.float32], axis: int,
                  step: int) -> NDArray[np.float64]:
    """Forward or backward difference over ``step`` pixels along ``axis``, whichever stays on the surface."""
    def shifted(a: NDArray[Any], by: int) -> NDArray[Any]:
        index = np.clip(np.arange(a.shape[axis]) + by, 0, a.shape[axis] - 1)
        return np.take(a, index, axis=axis)

    fwd, bwd = shifted(points, step) - points, points - shifted(points, -step)
    dz_f = np.abs(shifted(depth_m, step) - depth_m)
    dz_b = np.abs(depth_m - shifted(depth_m, -step))
    return np.where((dz_f <= dz_b)[..., None], fwd, bwd)


def incidence_deg(depth_m: FloatImage, camera: CameraIntrinsics) -> NDArray[np.float64]:
    """Angle (deg) between each pixel's viewing ray and its surface normal (90 = grazing).

    Normals come from a 5×5 median of the depth and differences over ``NORMAL_STEP_PX`` pixels,
    taken on the side that stays on the surface, so noise and depth edges do not read as grazing.
    """
    import cv2

    h, w = depth_m.shape
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)
    smooth = np.asarray(cv2.medianBlur(np.ascontiguousarray(depth_m, dtype=np.float32), 5), dtype=np.float32)
    z = smooth.astype(np.float64)
    points = np.stack([(u - camera.cx) / camera.fx * z, (v - camera.cy) / camera.fy * z, z], axis=-1)
    normal = np.cross(_smaller_step(points, smooth, 1, NORMAL_STEP_PX),
                      _smaller_step(points, smooth, 0, NORMAL_STEP_PX))
    norm = np.linalg.norm(normal, axis=-1) * np.linalg.norm(points, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.abs(np.einsum("hwk,hwk->hw", normal, points)) / norm
    angle_deg: NDArray[np.float64] = np.degrees(np.arccos(np.clip(np.nan_to_num(cos, nan=1.0), 0.0, 1.0)))
    return angle_deg


def grazing_dropout(profile: SensorProfile, incidence: NDArray[np.float64]) -> NDArray[np.float64]:
    """Chance of no return at ``incidence`` degrees: 0 up to ``grazing_deg``, 1 from ``grazing_full_deg``."""
    span = max(profile.grazing_full_deg - profile.grazing_deg, 1e-6)
    return np.clip((incidence - profile.grazing_deg) / span, 0.0, 1.0)


def _blocks(shape: tuple[int, int], block_px: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Uniform numbers constant over ``block_px`` squares: dropouts come as blobs, not single pixels."""
    h, w = shape
    b = max(1, block_px)
    coarse = rng.random((h // b + 1, w // b + 1))
    return np.repeat(np.repeat(coarse, b, axis=0), b, axis=1)[:h, :w]


def _noisy(depth_m: FloatImage, incidence: NDArray[np.float64] | None, profile: SensorProfile,
           rng: np.random.Generator) -> NDArray[np.float64]:
    """Axial Gaussian noise, then disparity quantisation."""
    z = depth_m.astype(np.float64)
    z = z + axial_sigma_m(profile, z, incidence) * rng.standard_normal(z.shape)
    if profile.quantised:
        fb = profile.disparity_focal_px * profile.baseline_m
        with np.errstate(divide="ignore"):
            disparity = np.where(z > 0, fb / np.where(z > 0, z, 1.0), 0.0)
        step = profile.disparity_step_px
        disparity = np.round(disparity / step) * step
        with np.errstate(divide="ignore"):
            z = np.where(disparity > 0, fb / np.where(disparity > 0, disparity, 1.0), 0.0)
    return z


def degrade_depth(depth_m: FloatImage, luma: NDArray[np.uint8] | None, camera: CameraIntrinsics,
                  profile: SensorProfile, rng: np.random.Generator) -> FloatImage:
    """The depth image ``profile``'s sensor would return for the ideal ``depth_m`` (0 = no return).

    ``luma`` (the registered grey image) marks dark and glossy surfaces; None skips those dropouts.
    """
    valid = depth_m > 0
    z = depth_m.astype(np.float32, copy=True)
    if profile.flying_fraction > 0:
        edge, across = depth_edges(depth_m, profile.edge_jump_frac)
        flying = edge & (rng.random(z.shape) < profile.flying_fraction)
        mix = rng.random(z.shape).astype(np.float32)
        z = np.where(flying, mix * z + (1 - mix) * across, z).astype(np.float32)
    needs_angle = profile.grazing_deg < 90 or profile.noise_angle_m > 0
    incidence = incidence_deg(depth_m, camera) if needs_angle else None
    noisy = _noisy(z, incidence, profile, rng)
    drop = ~valid | (noisy < profile.min_range_m) | (noisy > profile.max_range_m)
    if profile.shadows and profile.baseline_m > 0:
        drop |= projector_shadow(depth_m, camera.fx, profile.baseline_m)
    if incidence is not None and profile.grazing_deg < 90:
        drop |= rng.random(z.shape) < grazing_dropout(profile, incidence)
    if luma is not None and (profile.dark_dropout > 0 or profile.glossy_dropout > 0):
        chance = _blocks(z.shape, profile.dropout_block_px, rng)
        drop |= (luma < profile.dark_luma) & (chance < profile.dark_dropout)
        drop |= (luma > profile.glossy_luma) & (chance < profile.glossy_dropout)
    return np.where(drop, 0.0, noisy).astype(np.float32)
