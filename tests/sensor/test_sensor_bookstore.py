"""``--degrade structured-light`` on the shared bookstore matches the profile's documented figures.

Frames every ``STEP`` of the log are degraded by ``DegradedLog`` (what ``hiper convert --degrade``
writes, before the PNG/JPEG encoding) and compared with the clean log: the depth error per
range bin, the share of missing pixels, the shadow width at depth edges, the colour shift.
Skipped when ../shared/worlds is absent (HIPER_WORLDS points elsewhere).
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from hiper_cli.perceive.logs import open_log
from hiper_cli.sensor import get_profile
from hiper_cli.sensor.degrade import DegradedLog, luma
from hiper_cli.sensor.depth import depth_edges, error_std_m, grazing_dropout, incidence_deg, projector_shadow
from hiper_cli.types import Frame
from tests import WORLDS

BOOKSTORE = WORLDS / "bookstore"
STEP = 60
PROFILE = get_profile("structured-light")

pytestmark = pytest.mark.skipif(not (BOOKSTORE / "rgb.txt").is_file(),
                                reason=f"needs the shared bookstore log at {BOOKSTORE} (set HIPER_WORLDS)")


@cache
def _pairs() -> list[tuple[Frame, Frame]]:
    reader = open_log(BOOKSTORE)
    degraded = DegradedLog(reader, PROFILE, seed=1)
    return [(reader.read_frame(i), degraded.read_frame(i)) for i in range(0, len(reader), STEP)]


def _near_edges(depth_m: np.ndarray) -> np.ndarray:
    import cv2

    edge = depth_edges(depth_m, PROFILE.edge_jump_frac)[0].astype(np.uint8)
    return cv2.dilate(edge, np.ones((5, 5), np.uint8)) > 0


def test_depth_error_follows_the_model_within_10_percent_per_range_bin():
    bins = np.arange(0.5, 5.0, 0.5)
    squared, model, count = (np.zeros(len(bins) - 1) for _ in range(3))
    for clean, degraded in _pairs():
        z, y = clean.depth_m.astype(np.float64), degraded.depth_m.astype(np.float64)
        ok = (z > 0) & (y > 0) & ~_near_edges(clean.depth_m)
        index = np.digitize(z[ok], bins) - 1
        inside = (index >= 0) & (index < len(bins) - 1)
        np.add.at(squared, index[inside], ((y - z)[ok] ** 2)[inside])
        incidence = incidence_deg(clean.depth_m, clean.camera)[ok]
        np.add.at(model, index[inside], (error_std_m(PROFILE, z[ok], incidence) ** 2)[inside])
        np.add.at(count, index[inside], 1)
    assert np.all(count > 10_000), count
    ratio = np.sqrt(squared / count) / np.sqrt(model / count)
    assert np.all(np.abs(ratio - 1) < 0.10), dict(zip(bins[:-1].round(1).tolist(), ratio.round(3).tolist(),
                                                      strict=True))


def _certain_drops(clean: Frame) -> np.ndarray:
    return (clean.depth_m <= 0) | projector_shadow(clean.depth_m, clean.camera.fx, PROFILE.baseline_m)


def _grazing(clean: Frame) -> np.ndarray:
    return grazing_dropout(PROFILE, incidence_deg(clean.depth_m, clean.camera))


def test_dark_surfaces_lose_the_profiles_share_of_pixels():
    dark_pixels = dark_missing = 0
    for clean, degraded in _pairs():
        z = clean.depth_m
        dark = (luma(clean.rgb) < PROFILE.dark_luma) & (z > 0.6) & (z < 4.5)
        dark &= ~_certain_drops(clean) & ~_near_edges(z) & (_grazing(clean) == 0)
        dark_pixels += int(dark.sum())
        dark_missing += int((dark & (degraded.depth_m == 0)).sum())
    assert dark_pixels > 20_000
    assert dark_missing / dark_pixels == pytest.approx(PROFILE.dark_dropout, abs=0.05)


def test_share_of_missing_pixels_is_what_the_parameters_predict():
    predicted = measured = 0.0
    for clean, degraded in _pairs():
        z, grey = clean.depth_m, luma(clean.rgb)
        certain = _certain_drops(clean) | (z > PROFILE.max_range_m) | ((z > 0) & (z < PROFILE.min_range_m))
        lit = np.where(grey < PROFILE.dark_luma, PROFILE.dark_dropout,
                       np.where(grey > PROFILE.glossy_luma, PROFILE.glossy_dropout, 0.0))
        chance = 1 - (1 - lit) * (1 - _grazing(clean))
        predicted += float(np.where(certain, 1.0, chance).mean())
        measured += float((degraded.depth_m == 0).mean())
    frames = len(_pairs())
    clean_missing = np.mean([(c.depth_m == 0).mean() for c, _ in _pairs()])
    assert measured / frames > clean_missing + 0.02  # the sensor loses more than the clean log had
    assert measured / frames == pytest.approx(predicted / frames, abs=0.01)


def test_shadow_width_at_depth_edges_is_baseline_times_inverse_depth_step():
    predicted, measured = [], []
    for clean, degraded in _pairs():
        for v in range(0, clean.height, 4):
            row, out = clean.depth_m[v], degraded.depth_m[v]
            for u in np.flatnonzero((row[:-1] - row[1:] > 0.3) & (row[1:] > 0) & (row[:-1] > 0)) + 1:
                z_near, z_far = float(row[u]), float(row[u - 1])
                width = clean.camera.fx * PROFILE.baseline_m * (1 / z_near - 1 / z_far)
                lo = int(u - np.ceil(width) - 3)
                if lo < 0 or u + 3 >= len(row) or np.any(row[lo:u] <= 0):
                    continue
                if np.ptp(row[u:u + 3]) > 0.05 * z_near or np.ptp(row[lo:u]) > 0.1 * z_far:
                    continue  # only clean steps between two flat surfaces
                run = 0
                while u - 1 - run >= 0 and out[u - 1 - run] == 0:
                    run += 1
                predicted.append(width)
                measured.append(run)
    error = np.array(measured) - np.array(predicted)
    assert len(error) > 200
    assert np.median(predicted) > 2  # shadows worth measuring
    lower, median, upper = np.percentile(error, [25, 50, 75])
    assert lower >= -1.0 and upper <= 1.0 and abs(median) <= 0.6


def test_colour_is_shifted_against_depth_by_the_profiles_misregistration():
    import cv2

    shifts = [cv2.phaseCorrelate(clean.rgb[..., 1].astype(np.float64),
                                 degraded.rgb[..., 1].astype(np.float64))[0] for clean, degraded in _pairs()]
    assert np.median(np.array(shifts), axis=0) == pytest.approx(PROFILE.misregistration_px, abs=0.3)


def test_pose_source_drifts_a_few_centimetres():
    reader = open_log(BOOKSTORE)
    degraded = DegradedLog(reader, PROFILE, seed=1)
    error = np.linalg.norm(degraded.T_map_cam_est[:, :3, 3] - degraded.T_map_cam_true[:, :3, 3], axis=1)
    assert 0.005 < float(error.max()) < 0.15
