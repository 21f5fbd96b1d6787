"""Triangle meshes of the simulated worlds: boxes, cylinders, spheres and a human body.

A ``Mesh`` holds vertices (N, 3) float64 metres, triangles (M, 3) int64 and one RGB colour
per triangle (M, 3) float64 in [0, 1]. Meshes are built in a local frame and placed with
``Mesh.transformed``; ``Mesh.concat`` joins parts into one object.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Mesh",
    "box",
    "cylinder",
    "human",
    "rot_z",
    "sphere",
]

Color = tuple[float, float, float]

# Triangles of the unit cube with outward normals (counter-clockwise seen from outside).
_CUBE_V = np.array(
    [[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)], dtype=np.float64
)
_CUBE_T = np.array(
    [
        [0, 1, 3],
        [0, 3, 2],  # -x
        [4, 6, 7],
        [4, 7, 5],  # +x
        [0, 4, 5],
        [0, 5, 1],  # -y
        [2, 3, 7],
        [2, 7, 6],  # +y
        [0, 2, 6],
        [0, 6, 4],  # -z
        [1, 5, 7],
        [1, 7, 3],  # +z
    ],
    dtype=np.int64,
)


@dataclass(frozen=True)
class Mesh:
    """Vertices (N, 3) metres, triangles (M, 3) vertex indices, colours (M, 3) RGB in [0, 1]."""

    vertices: NDArray[np.float64]
    triangles: NDArray[np.int64]
    colors: NDArray[np.float64]

    @staticmethod
    def concat(parts: Sequence[Mesh]) -> Mesh:
        offsets = np.cumsum([0] + [len(p.vertices) for p in parts[:-1]])
        return Mesh(
            np.concatenate([p.vertices for p in parts]),
            np.concatenate([p.triangles + o for p, o in zip(parts, offsets, strict=True)]),
            np.concatenate([p.colors for p in parts]),
        )

    def transformed(self, T: NDArray[np.float64]) -> Mesh:
        """This mesh with every vertex mapped by the 4×4 transform ``T``."""
        return Mesh(self.vertices @ T[:3, :3].T + T[:3, 3], self.triangles, self.colors)

    def translated(self, offset: Sequence[float]) -> Mesh:
        return Mesh(self.vertices + np.asarray(offset, dtype=np.float64), self.triangles, self.colors)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)


def rot_z(yaw_rad: float, t: Sequence[float] = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """4×4 rotation about z by ``yaw_rad`` followed by the translation ``t``."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = t
    return T


def box(lo: Sequence[float], hi: Sequence[float], color: Color) -> Mesh:
    """The axis-aligned box between corners ``lo`` and ``hi``."""
    lo_a, hi_a = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    vertices = (lo_a + hi_a) / 2.0 + _CUBE_V * (hi_a - lo_a)
    return Mesh(vertices, _CUBE_T.copy(), np.tile(np.asarray(color, dtype=np.float64), (12, 1)))


def checker_floor(
    lo: Sequence[float], hi: Sequence[float], tile_m: float, colors: tuple[Color, Color]
) -> Mesh:
    """A horizontal slab ``lo``-``hi`` whose top face is a checkerboard of ``tile_m`` tiles."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    xs = np.append(np.arange(x0, x1, tile_m), x1)
    ys = np.append(np.arange(y0, y1, tile_m), y1)
    parts = [box((x0, y0, z0), (x1, y1, z1 - 0.001), colors[0])]
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            parts.append(_quad_z(xs[i], ys[j], xs[i + 1], ys[j + 1], z1, colors[(i + j) % 2]))
    return Mesh.concat(parts)


def _quad_z(x0: float, y0: float, x1: float, y1: float, z: float, color: Color) -> Mesh:
    v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]], dtype=np.float64)
    t = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)
    return Mesh(v, t, np.tile(np.asarray(color, dtype=np.float64), (2, 1)))


def cylinder(
    radius_m: float, z0: float, z1: float, color: Color, segments: int = 12, cap: Color | None = None
) -> Mesh:
    """A closed cylinder around the z axis from ``z0`` to ``z1``."""
    a = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    ring = np.stack([radius_m * np.cos(a), radius_m * np.sin(a)], axis=1)
    bottom = np.column_stack([ring, np.full(segments, z0)])
    top = np.column_stack([ring, np.full(segments, z1)])
    vertices = np.vstack([bottom, top, [[0.0, 0.0, z0], [0.0, 0.0, z1]]])
    tris = []
    cb, ct = 2 * segments, 2 * segments + 1
    for i in range(segments):
        j = (i + 1) % segments
        tris += [[i, j, segments + j], [i, segments + j, segments + i]]
    for i in range(segments):
        j = (i + 1) % segments
        tris += [[cb, j, i], [ct, segments + i, segments + j]]
    colors = [color] * (2 * segments) + [cap or color] * (2 * segments)
    return Mesh(vertices, np.array(tris, dtype=np.int64), np.array(colors, dtype=np.float64))


def frustum(r0: float, r1: float, z0: float, z1: float, color: Color, segments: int = 12) -> Mesh:
    """A cone segment from radius ``r0`` at ``z0`` to ``r1`` at ``z1`` (a bottle's shoulder)."""
    mesh = cylinder(1.0, z0, z1, color, segments)
    v = mesh.vertices.copy()
    v[:segments, :2] *= r0
    v[segments : 2 * segments, :2] *= r1
    return Mesh(v, mesh.triangles, mesh.colors)


def sphere(radius_m: float, color: Color, rings: int = 6, segments: int = 10) -> Mesh:
    """A UV sphere centred at the origin."""
    vertices = [[0.0, 0.0, radius_m]]
    for i in range(1, rings):
        phi = math.pi * i / rings
        for j in range(segments):
            theta = 2 * math.pi * j / segments
            vertices.append(
                [
                    radius_m * math.sin(phi) * math.cos(theta),
                    radius_m * math.sin(phi) * math.sin(theta),
                    radius_m * math.cos(phi),
                ]
            )
    vertices.append([0.0, 0.0, -radius_m])
    last = len(vertices) - 1
    tris = []
    for j in range(segments):
        tris.append([0, 1 + j, 1 + (j + 1) % segments])
    for i in range(rings - 2):
        for j in range(segments):
            a = 1 + i * segments + j
            b = 1 + i * segments + (j + 1) % segments
            tris += [[a, a + segments, b + segments], [a, b + segments, b]]
    base = 1 + (rings - 2) * segments
    for j in range(segments):
        tris.append([last, base + (j + 1) % segments, base + j])
    return Mesh(
        np.array(vertices, dtype=np.float64),
        np.array(tris, dtype=np.int64),
        np.tile(np.asarray(color, dtype=np.float64), (len(tris), 1)),
    )


SKIN_TONES: tuple[Color, ...] = (
    (0.94, 0.78, 0.66),
    (0.80, 0.60, 0.45),
    (0.55, 0.38, 0.26),
    (0.36, 0.24, 0.16),
)


def human(
    height_m: float,
    skin: Color,
    shirt: Color,
    trousers: Color,
    hair: Color = (0.15, 0.1, 0.05),
    stride: float = 0.0,
) -> Mesh:
    """A standing person facing +x, feet on z = 0, centred on the z axis.

    Head, neck, torso, two arms with hands and two legs with shoes, in proportion to
    ``height_m`` (an adult is about 7.5 heads tall). ``stride`` in [-1, 1] swings the legs
    and arms (0 = standing). The mesh fits inside a vertical cylinder of radius
    0.26 × height_m / 1.75, so a yaw-invariant box bounds it.
    """
    s = height_m / 1.75
    head_r = 0.115 * s
    leg_len = 0.84 * s
    hip_z = leg_len
    shoulder_z = 1.46 * s
    parts: list[Mesh] = []
    swing = 0.18 * s * stride
    for side in (-1.0, 1.0):
        y = side * 0.095 * s
        dx = swing * side
        leg = cylinder(0.075 * s, 0.08 * s, hip_z + 0.02 * s, trousers, 8)
        parts.append(_lean(leg, dx, hip_z).translated((0.0, y, 0.0)))
        parts.append(
            box(
                (-0.06 * s + dx, y - 0.055 * s, 0.0),
                (0.13 * s + dx, y + 0.055 * s, 0.08 * s),
                (0.12, 0.12, 0.12),
            )
        )
        ay = side * 0.215 * s
        arm = cylinder(0.05 * s, 0.84 * s, shoulder_z - 0.02 * s, shirt, 8)
        parts.append(_lean(arm, -dx * 0.8, shoulder_z).translated((0.0, ay, 0.0)))
        hand = sphere(0.05 * s, skin, 4, 8).translated((-dx * 0.8 * 0.7, ay, 0.80 * s))
        parts.append(hand)
    parts.append(
        box((-0.11 * s, -0.17 * s, hip_z - 0.04 * s), (0.11 * s, 0.17 * s, hip_z + 0.12 * s), trousers)
    )
    parts.append(box((-0.12 * s, -0.18 * s, hip_z + 0.10 * s), (0.12 * s, 0.18 * s, shoulder_z), shirt))
    parts.append(cylinder(0.05 * s, shoulder_z - 0.01 * s, shoulder_z + 0.07 * s, skin, 8))
    head_z = height_m - head_r
    parts.append(sphere(head_r, skin).translated((0.0, 0.0, head_z)))
    # Hair: a cap over the back and the top of the head.
    cap = sphere(head_r * 1.06, hair)
    keep = cap.vertices[cap.triangles].mean(axis=1)
    mask = (keep[:, 2] > head_r * 0.25) | (keep[:, 0] < -head_r * 0.3)
    parts.append(Mesh(cap.vertices, cap.triangles[mask], cap.colors[mask]).translated((0.0, 0.0, head_z)))
    return Mesh.concat(parts)


def _lean(mesh: Mesh, dx_bottom: float, pivot_z: float) -> Mesh:
    """Shear a limb hanging from ``pivot_z`` so its lower end moves by ``dx_bottom`` along x."""
    v = mesh.vertices.copy()
    z_min = float(v[:, 2].min())
    if pivot_z - z_min > 1e-9:
        v[:, 0] += dx_bottom * (pivot_z - v[:, 2]) / (pivot_z - z_min)
    return Mesh(v, mesh.triangles, mesh.colors)
