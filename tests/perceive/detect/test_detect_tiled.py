"""The tiled look (``detect/tiled.py``): tiles cover the image, a small thing found in a tile is
placed in the image's pixels, a thing cut by a tile's inner edge is left to the whole look."""

import numpy as np
import pytest

from hiper_cli.errors import ConfigError
from hiper_cli.perceive.detect.tiled import TiledDetector, merge_detections, tile_boxes
from hiper_cli.types import CameraIntrinsics, Detections, Frame

INPUT_PX = 416
LEAST_PX = 24


class ShrinkingDetector:
    """Stands for a detector of fixed input (YOLOX-Nano, 416 px): it finds the red squares of
    the image it is given only where the square, shrunk with the image to ``INPUT_PX``, is still
    ``LEAST_PX`` across. Records the size of each image it was given."""

    name = "shrinking"
    class_names = ("book",)

    def __init__(self):
        self.sizes = []

    def detect(self, frame):
        self.sizes.append((frame.width, frame.height))
        scale = INPUT_PX / max(frame.width, frame.height)
        red = (frame.rgb[:, :, 0] > 200) & (frame.rgb[:, :, 1] < 50)
        boxes = []
        for x0, y0, x1, y1 in _squares(red):
            if max(x1 - x0, y1 - y0) * scale >= LEAST_PX:
                boxes.append([x0, y0, x1, y1])
        return Detections(np.array(boxes, dtype=np.float64).reshape(-1, 4), ("book",) * len(boxes),
                          np.full(len(boxes), 0.8))


def _squares(mask):
    """Boxes of the connected red regions (4-connectivity), xyxy."""
    import cv2

    n, _labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=4)
    return [(x, y, x + w, y + h) for x, y, w, h, _ in stats[1:n].tolist()]


def frame_with(squares, width=640, height=480):
    rgb = np.full((height, width, 3), 90, dtype=np.uint8)
    for x0, y0, x1, y1 in squares:
        rgb[y0:y1, x0:x1] = (255, 0, 0)
    cam = CameraIntrinsics(width, height, 525.0, 525.0, width / 2 - 0.5, height / 2 - 0.5)
    return Frame(0.0, rgb, np.ones((height, width), np.float32), cam, np.eye(4), 0)


def test_tiles_cover_the_image_and_overlap():
    tiles = tile_boxes(640, 480, 2, 2, 0.25)
    assert tiles == [(0, 0, 366, 275), (274, 0, 640, 275), (0, 205, 366, 480), (274, 205, 640, 480)]
    covered = np.zeros((480, 640), dtype=int)
    for x0, y0, x1, y1 in tiles:
        covered[y0:y1, x0:x1] += 1
    assert covered.min() == 1 and covered.max() == 4
    assert tile_boxes(640, 480, 1, 1, 0.0) == [(0, 0, 640, 480)]
    with pytest.raises(ConfigError, match="overlap"):
        tile_boxes(640, 480, 2, 2, 1.0)


def test_a_small_thing_the_whole_look_misses_is_found_in_its_tile_at_its_image_pixels():
    frame = frame_with([(500, 380, 530, 410)])  # 30 px: 19.5 px in the whole look, 34 in a tile
    detector = ShrinkingDetector()
    assert len(detector.detect(frame)) == 0
    found = TiledDetector(detector, 2, 2, 0.25).detect(frame)
    assert found.class_names == ("book",)
    assert found.xyxy[0] == pytest.approx([500, 380, 530, 410])
    assert (640, 480) in detector.sizes and (366, 275) in detector.sizes


def test_a_thing_cut_by_a_tiles_inner_edge_is_left_to_the_whole_look():
    # 120 px wide across x = 366 (the first tile's right edge), inside the second tile's left part:
    # the first tile sees it cut; the whole look and the second tile see it whole
    frame = frame_with([(300, 100, 420, 140)])
    found = TiledDetector(ShrinkingDetector(), 2, 2, 0.25).detect(frame)
    assert len(found) == 1 and found.xyxy[0] == pytest.approx([300, 100, 420, 140])
    without_whole = TiledDetector(ShrinkingDetector(), 2, 2, 0.25, whole=False).detect(frame)
    assert len(without_whole) == 1  # the second tile's, not the first tile's cut one
    assert without_whole.xyxy[0] == pytest.approx([300, 100, 420, 140])
    # wider than a tile's overlap: no tile holds it whole, and without the whole look nothing does
    wide = frame_with([(200, 100, 440, 140)])
    assert len(TiledDetector(ShrinkingDetector(), 2, 2, 0.25, whole=False).detect(wide)) == 0
    assert len(TiledDetector(ShrinkingDetector(), 2, 2, 0.25).detect(wide)) == 1


def test_merging_keeps_one_box_per_object_and_class():
    a = Detections(np.array([[0, 0, 10, 10], [50, 50, 60, 60]], float), ("cup", "cup"), np.array([0.4, 0.9]))
    b = Detections(np.array([[1, 0, 10, 10], [0, 0, 10, 10]], float), ("cup", "bowl"), np.array([0.7, 0.5]))
    merged = merge_detections([a, b, Detections.empty()])
    assert sorted(zip(merged.class_names, merged.scores.tolist(), strict=True)) == [
        ("bowl", 0.5), ("cup", 0.7), ("cup", 0.9)]
    assert len(merge_detections([])) == 0
