"""Options of background recognition, with the paper's values as named defaults.

Paper section IV-C/D: planes are extracted from keyframes at the mapping rate (2 Hz), each
plane is classified by the alignment of its normal and its height (wall, floor, ceiling,
table, unknown) and merged into instances by criteria of increasing cost (class, alignment,
box overlap, contour overlap). Lengths in metres, angles in degrees.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from hiper_cli.errors import ConfigError

__all__ = ["METHODS", "BackgroundConfig"]

METHODS: tuple[str, ...] = ("fast", "ransac")


@dataclass(frozen=True)
class BackgroundConfig:
    """Every knob of the background stage.

    Extraction (``method="fast"``): the depth image is sampled every ``stride_px`` pixels,
    grouped into cells of ``cell_px`` samples a side, each planar cell gets a least-squares
    plane, and neighbouring cells with similar planes are grown into regions (PEAC/CAPE
    style). ``method="ransac"`` runs open3d's ``segment_plane`` (the paper's SACSegmentation)
    on the same samples instead.
    """

    method: str = "fast"
    keyframe_hz: float = 2.0  # the paper's mapping rate
    min_depth_m: float = 0.3
    max_depth_m: float = 6.0
    # fast extraction
    stride_px: int = 4
    cell_px: int = 5
    cell_noise_m: float = 0.0025  # plane RMS allowed in a cell at 1 m (grows with depth squared)
    # fraction of valid samples a cell needs: half is enough to fit its plane and test its noise;
    # a structured-light camera loses most returns of a table top seen at grazing incidence
    # (docs/sensors.md: 75-88 degrees), and at 0.9 no top of the degraded bookstore was found
    cell_min_valid: float = 0.5
    # a kink in inverse depth above this (1/m) separates surfaces; on a plane 1/z is linear in
    # the image, so its second difference is ~0 even at grazing angles
    jump_inv_m: float = 0.02
    grow_angle_deg: float = 12.0
    # far cells may differ by the angle their depth noise explains (``planes._grow_angle``)
    grow_noise_angle: bool = True
    grow_offset_m: float = 0.04
    inlier_m: float = 0.03  # point-to-plane distance of an inlier at 1 m (grows with depth)
    min_plane_cells: int = 4
    refine_passes: int = 2  # assign samples to the closest plane and refit, this many times
    # a plane keeps only the samples it reaches from its own cells through neighbours whose
    # depths differ by at most this fraction (a chair back behind a table top's far edge, at
    # the top's height, is coplanar with it but 0.45 m behind; 0: off)
    join_jump_frac: float = 0.05
    # ransac extraction (the paper's method)
    ransac_max_planes: int = 8
    ransac_iterations: int = 500
    ransac_stride_px: int = 8
    ransac_min_points: int = 150
    # observations
    min_area_m2: float = 0.15
    pixel_sample: int = 64  # inlier pixels kept per observation for evaluation
    contour_epsilon_px: float = 1.0
    # classification in the map frame (z up)
    horizontal_deg: float = 10.0  # floor, ceiling, table normals within this of vertical
    vertical_deg: float = 10.0  # wall normals within this of horizontal
    floor_max_height_m: float = 0.1  # a cart's low shelf (0.15 m) is not floor
    ceiling_min_height_m: float = 1.9
    table_min_height_m: float = 0.6  # above seats, beds and low shelves (0.45-0.56 m)
    table_max_height_m: float = 1.1
    table_min_area_m2: float = 0.15
    table_max_extent_m: float = 3.5
    # a table top stands on legs: below its near edge the camera sees under it, not a solid
    # front (a box stack, a cabinet, a bed; ``under.py``)
    table_needs_legs: bool = True
    # a top goes on behind what stands on it or in front of it (``hidden.py``): plane points
    # this far beyond a top's seen edge that something nearer hid join two pieces of it (0: off)
    table_bridge_m: float = 0.2
    wall_min_height_m: float = 1.2  # a standing person is ~1.8 m tall but narrow and not flat
    wall_min_width_m: float = 1.0
    wall_min_area_m2: float = 1.0
    wall_top_min_m: float = 1.5  # the observed part reaches this high (furniture rarely does)
    # wall bounds (``bounds.py``): a wall reaches the ceiling and the floor or the image's edge;
    # probes this far beyond its top and bottom edge, in every column, must see the surface go
    # on (within the tolerances of the plane's depth), not farther
    wall_bounds: bool = True
    wall_probe_gap_px: float = 8.0
    wall_probe_reach_px: float = 48.0  # probes walk out to this, over occluders in front
    wall_probe_tolerance_m: float = 0.05
    # a probe lies on the plane within wall_probe_tolerance_m + wall_probe_tolerance_frac times
    # its depth, but no deeper than wall_front_min_m less the depth noise there (cell_noise_m
    # times depth squared): 5 % of 4.1-4.6 m (0.25-0.28 m) took a free-standing shelf's book
    # rows, 0.2-0.25 m behind its frame, for the plane going on (``bounds._probe``)
    wall_probe_tolerance_frac: float = 0.05
    wall_probe_max_depth_m: float = 4.5  # no return where the plane would be nearer: nothing there
    wall_probe_min_columns: int = 3
    wall_open_share: float = 0.5  # of the columns with evidence, this share open: not a wall
    # a vertical plane seen up to the image's top and down to an occluder in front is as tall
    # as the view shows it: the wall height test is waived (``bounds.view_bounded``)
    wall_view_bounded: bool = True
    # a view whose depth noise (cell_noise_m times its range squared) exceeds this is no
    # evidence of a wall: a shelf front's rows and a door flush with its wall hide in it. A wall
    # instance no nearer view joined is withdrawn when the log ends (``wall_range.py``; 0.045:
    # 4.2 m with the default noise model; 0: every view counts)
    wall_view_max_noise_m: float = 0.045
    # a furniture front stands before a wall (``fronts.py``): past a side edge the camera sees a
    # plane parallel to it this far behind; deeper than a door's recess in its wall (a wall's
    # thickness), no deeper than furniture (wardrobes, fridges, shelves: 0.3-0.8 m)
    wall_fronts: bool = True
    wall_front_min_m: float = 0.25
    wall_front_max_m: float = 1.0
    # merging (Algorithm 2)
    merge_angle_deg: float = 10.0
    merge_offset_m: float = 0.1
    merge_box_margin_m: float = 0.3
    merge_contour_margin_m: float = 0.15
    # seeing a known instance again (``sighting.py``): its last_seen follows the camera when
    # this many pixels (of 640x480, scaled) lie on it, tested every stride-th pixel, at most
    # every refresh_s (0 pixels: off)
    sighting_min_pixels: int = 400
    sighting_stride_px: int = 8
    sighting_refresh_s: float = 1.0

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ConfigError(f"background method {self.method!r}; expected one of {', '.join(METHODS)}")
        if self.keyframe_hz <= 0:
            raise ConfigError(f"background keyframe_hz must be positive, got {self.keyframe_hz}")
        if self.stride_px < 1 or self.cell_px < 2 or self.ransac_stride_px < 1:
            raise ConfigError("background stride_px, ransac_stride_px must be >= 1 and cell_px >= 2")
        if self.sighting_stride_px < 1 or self.sighting_refresh_s < 0:
            raise ConfigError(
                f"background sighting_stride_px must be >= 1 (got {self.sighting_stride_px}) and "
                f"sighting_refresh_s >= 0 (got {self.sighting_refresh_s})"
            )
        if not 0 < self.min_depth_m < self.max_depth_m:
            raise ConfigError(
                f"background depth range {self.min_depth_m}..{self.max_depth_m} m is empty; "
                "expected 0 < min_depth_m < max_depth_m"
            )

    @classmethod
    def from_options(cls, **options: Any) -> BackgroundConfig:
        """Build from keyword options, checked by ``hiper_cli.validate.typed_options`` (known
        name, type, finite); an unknown name raises ``ConfigError``."""
        from hiper_cli.validate import typed_options

        return cls(**typed_options(cls, options, "-o background"))
