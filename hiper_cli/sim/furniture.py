"""Furniture and object meshes, built at the origin facing +x, feet on z = 0.

Each function returns a ``Mesh`` in its local frame; ``worlds`` turns and places it.
Shapes are chosen for a COCO detector: chairs with four legs and a back, bottles with a
shoulder and a neck, couches with arms and cushions.
"""

from __future__ import annotations

import numpy as np

from hiper_cli.sim.meshes import Color, Mesh, box, cylinder, frustum, human, sphere

__all__ = [
    "bed",
    "bottle",
    "cart",
    "chair",
    "couch",
    "cup",
    "framed_person",
    "plant",
    "shelf",
    "stairs",
    "table",
    "tv",
]


def table(length_m: float, width_m: float, height_m: float, top: Color, legs: Color) -> Mesh:
    """A table (or desk) with a 4 cm top and four square legs."""
    lx, ly = length_m / 2.0, width_m / 2.0
    parts = [box((-lx, -ly, height_m - 0.04), (lx, ly, height_m), top)]
    for sx in (-1, 1):
        for sy in (-1, 1):
            cx, cy = sx * (lx - 0.06), sy * (ly - 0.06)
            parts.append(box((cx - 0.025, cy - 0.025, 0.0), (cx + 0.025, cy + 0.025, height_m - 0.04), legs))
    return Mesh.concat(parts)


def chair(seat: Color, frame: Color) -> Mesh:
    """A dining chair facing +x: four legs, a seat at 0.45 m and a back rising to 0.9 m."""
    parts = [box((-0.22, -0.22, 0.42), (0.22, 0.22, 0.47), seat)]
    for sx in (-1, 1):
        for sy in (-1, 1):
            cx, cy = sx * 0.19, sy * 0.19
            parts.append(box((cx - 0.02, cy - 0.02, 0.0), (cx + 0.02, cy + 0.02, 0.42), frame))
    parts.append(box((-0.22, -0.2, 0.47), (-0.18, -0.16, 0.92), frame))
    parts.append(box((-0.22, 0.16, 0.47), (-0.18, 0.2, 0.92), frame))
    parts.append(box((-0.22, -0.2, 0.62), (-0.18, 0.2, 0.9), seat))
    return Mesh.concat(parts)


def couch(length_m: float, fabric: Color, cushion: Color) -> Mesh:
    """A three-seat couch facing +x: base, back, two arms and seat cushions."""
    ly = length_m / 2.0
    parts = [
        box((-0.45, -ly, 0.08), (0.45, ly, 0.42), fabric),
        box((-0.45, -ly, 0.42), (-0.25, ly, 0.85), fabric),
        box((-0.45, -ly, 0.42), (0.45, -ly + 0.18, 0.62), fabric),
        box((-0.45, ly - 0.18, 0.42), (0.45, ly, 0.62), fabric),
    ]
    seats = 3
    width = (length_m - 0.36) / seats
    for k in range(seats):
        y0 = -ly + 0.18 + k * width
        parts.append(box((-0.25, y0 + 0.01, 0.42), (0.43, y0 + width - 0.01, 0.52), cushion))
        parts.append(box((-0.25, y0 + 0.01, 0.52), (-0.13, y0 + width - 0.01, 0.8), cushion))
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(
                box(
                    (sx * 0.4 - 0.03, sy * (ly - 0.05) - 0.03, 0.0),
                    (sx * 0.4 + 0.03, sy * (ly - 0.05) + 0.03, 0.08),
                    (0.1, 0.08, 0.06),
                )
            )
    return Mesh.concat(parts)


def bed(length_m: float, width_m: float, frame: Color, sheet: Color, pillow: Color) -> Mesh:
    """A bed along +x (head board at -x): frame, mattress, pillow, blanket."""
    lx, ly = length_m / 2.0, width_m / 2.0
    return Mesh.concat(
        [
            box((-lx, -ly, 0.0), (lx, ly, 0.3), frame),
            box((-lx + 0.02, -ly + 0.02, 0.3), (lx - 0.02, ly - 0.02, 0.5), (0.95, 0.95, 0.93)),
            box((lx * -1 + 0.05, -ly + 0.1, 0.5), (-lx + 0.45, ly - 0.1, 0.6), pillow),
            box((-lx + 0.6, -ly + 0.0, 0.5), (lx - 0.0, ly - 0.0, 0.56), sheet),
            box((-lx - 0.05, -ly, 0.0), (-lx, ly, 0.95), frame),
        ]
    )


def shelf(width_m: float, height_m: float, wood: Color, rng: np.random.Generator) -> Mesh:
    """A book shelf 0.35 m deep facing +x, with rows of coloured books."""
    ly = width_m / 2.0
    parts = [
        box((-0.175, -ly, 0.0), (-0.155, ly, height_m), wood),
        box((-0.175, -ly, 0.0), (0.175, -ly + 0.02, height_m), wood),
        box((-0.175, ly - 0.02, 0.0), (0.175, ly, height_m), wood),
    ]
    levels = max(2, int(height_m / 0.38))
    for k in range(levels + 1):
        z = k * (height_m - 0.02) / levels
        parts.append(box((-0.175, -ly, z), (0.175, ly, z + 0.02), wood))
        if k == levels:
            break
        y = -ly + 0.03
        while y < ly - 0.08:
            w = float(rng.uniform(0.025, 0.06))
            h = float(rng.uniform(0.18, 0.3))
            color = tuple(float(c) for c in rng.uniform(0.1, 0.85, 3))
            parts.append(box((-0.15, y, z + 0.02), (0.1, y + w, z + 0.02 + h), color))  # type: ignore[arg-type]
            y += w + 0.004
    return Mesh.concat(parts)


def bottle(height_m: float, glass: Color, cap: Color = (0.9, 0.9, 0.9)) -> Mesh:
    """A bottle: body, shoulder, neck and cap."""
    r = 0.11 * height_m + 0.01
    body = 0.62 * height_m
    return Mesh.concat(
        [
            cylinder(r, 0.0, body, glass, 14),
            frustum(r, 0.35 * r, body, 0.8 * height_m, glass, 14),
            cylinder(0.35 * r, 0.8 * height_m, 0.96 * height_m, glass, 10),
            cylinder(0.4 * r, 0.96 * height_m, height_m, cap, 10),
        ]
    )


def cup(color: Color) -> Mesh:
    """A mug 10 cm tall with a handle."""
    return Mesh.concat(
        [
            cylinder(0.04, 0.0, 0.1, color, 14, cap=(0.25, 0.15, 0.1)),
            box((0.04, -0.008, 0.025), (0.07, 0.008, 0.035), color),
            box((0.06, -0.008, 0.025), (0.07, 0.008, 0.085), color),
            box((0.04, -0.008, 0.075), (0.07, 0.008, 0.085), color),
        ]
    )


def plant(pot: Color) -> Mesh:
    """A potted plant: a pot and a few green leaf blobs."""
    parts = [frustum(0.12, 0.16, 0.0, 0.3, pot, 14)]
    for k, (dx, dy, dz, r) in enumerate(
        [(0.0, 0.0, 0.55, 0.2), (0.1, 0.05, 0.45, 0.14), (-0.08, -0.06, 0.48, 0.15), (0.02, -0.1, 0.7, 0.12)]
    ):
        green = (0.15 + 0.05 * k, 0.45 + 0.05 * k, 0.15)
        parts.append(sphere(r, green, 5, 8).translated((dx, dy, dz)))
    parts.append(cylinder(0.02, 0.3, 0.5, (0.3, 0.22, 0.1), 6))
    return Mesh.concat(parts)


def framed_person(
    width_m: float,
    height_m: float,
    frame: Color,
    backdrop: Color,
    figure_h_m: float,
    depth_m: float = 0.03,
    rng: np.random.Generator | None = None,
) -> Mesh:
    """A flat picture facing +x (its back at x = 0): a frame, a backdrop and a painted person.

    The person is a flattened human mesh, so an RGB detector sees a person where the depth
    shows a flat wall object (the paper's false-positive trap).
    """
    lw, base = width_m / 2.0, 0.0
    parts = [
        box((0.0, -lw, base), (depth_m, lw, base + height_m), frame),
        box(
            (depth_m, -lw + 0.04, base + 0.04), (depth_m + 0.002, lw - 0.04, base + height_m - 0.04), backdrop
        ),
    ]
    g = rng or np.random.default_rng(0)
    skin = (0.9, 0.72, 0.6) if g.random() < 0.5 else (0.55, 0.38, 0.26)
    shirt = tuple(float(c) for c in g.uniform(0.1, 0.9, 3))
    figure = human(figure_h_m, skin, shirt, (0.15, 0.18, 0.3))  # type: ignore[arg-type]
    v = figure.vertices.copy()
    # Turn the figure to face +x flat: keep y (width) and z (height), squash x.
    v[:, 0] = depth_m + 0.004 + 0.004 * (v[:, 0] - v[:, 0].min()) / max(np.ptp(v[:, 0]), 1e-9)
    v[:, 2] += base + (height_m - figure_h_m) / 2.0
    parts.append(Mesh(v, figure.triangles, figure.colors))
    return Mesh.concat(parts)


def tv(width_m: float, rng: np.random.Generator) -> Mesh:
    """A flat TV screen facing +x (back at x = 0) showing a person, 16:9."""
    h = width_m * 9.0 / 16.0
    screen = framed_person(width_m, h, (0.05, 0.05, 0.05), (0.35, 0.55, 0.75), 0.85 * h, 0.05, rng)
    return screen


def cart(rng: np.random.Generator) -> Mesh:
    """A care cart along +x: three trays on four posts, wheels and a push handle."""
    body = (0.85, 0.87, 0.9)
    parts = []
    for z in (0.15, 0.5, 0.85):
        parts.append(box((-0.4, -0.25, z), (0.4, 0.25, z + 0.03), body))
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(
                box(
                    (sx * 0.38 - 0.02, sy * 0.23 - 0.02, 0.1),
                    (sx * 0.38 + 0.02, sy * 0.23 + 0.02, 0.9),
                    (0.6, 0.6, 0.62),
                )
            )
            parts.append(cylinder(0.05, 0.0, 0.1, (0.1, 0.1, 0.1), 8).translated((sx * 0.35, sy * 0.22, 0.0)))
    parts.append(box((-0.44, -0.2, 0.9), (-0.41, 0.2, 1.0), (0.2, 0.45, 0.75)))
    for k in range(3):
        color = tuple(float(c) for c in rng.uniform(0.2, 0.9, 3))
        parts.append(box((-0.3 + 0.22 * k, -0.15, 0.88), (-0.15 + 0.22 * k, 0.15, 0.98), color))  # type: ignore[arg-type]
    return Mesh.concat(parts)


def stairs(steps: int, width_m: float, color: Color) -> Mesh:
    """A flight of steps rising along +x, 0.28 m deep and 0.17 m high each."""
    parts = []
    for k in range(steps):
        shade = 0.9 if k % 2 else 1.0
        parts.append(
            box(
                (k * 0.28, -width_m / 2, 0.0),
                ((k + 1) * 0.28, width_m / 2, (k + 1) * 0.17),
                (color[0] * shade, color[1] * shade, color[2] * shade),
            )
        )
    return Mesh.concat(parts)
