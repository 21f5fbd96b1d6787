"""Procedural world presets (``house``, ``hospital``, ``office``), seeded.

A ``World`` holds its static objects as meshes in the map frame (each one ground-truth
instance), the 2D footprints that block walking and driving, the people and carts that
move, and the waypoints the robot visits. The room layout is fixed per preset with seeded
jitter of its dimensions; furniture placement, colours, object counts and the people vary
with the seed. Map frame: z up, floor at z = 0; all furniture is turned by multiples of
90° so every static box is axis-aligned and exact.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from hiper_cli.errors import ConfigError
from hiper_cli.model import Box3D
from hiper_cli.sim import furniture as fu
from hiper_cli.sim.meshes import SKIN_TONES, Color, Mesh, box, checker_floor, rot_z

__all__ = ["WORLDS", "CartSpec", "Rect", "SimObject", "WalkerSpec", "World", "make_world"]

Rect = tuple[float, float, float, float]  # x0, y0, x1, y1 in the map frame
XY = tuple[float, float]

WALL_THICKNESS_M = 0.06
DOOR_HEIGHT_M = 2.1


@dataclass(frozen=True)
class SimObject:
    """One static ground-truth instance: its mesh in the map frame and what it is."""

    id: int
    name: str
    class_name: str
    layer: str
    mesh: Mesh
    plane: tuple[float, float, float, float] | None = None

    @property
    def box(self) -> Box3D:
        lo, hi = self.mesh.bounds()
        return Box3D((lo + hi) / 2.0, hi - lo)


@dataclass(frozen=True)
class WalkerSpec:
    """A person: body, preferred speed and where they walk.

    ``goals``: fixed positions visited in turn (cyclically, from ``start_goal``); empty means
    random goals anywhere walkable, with a pause of ``pause_s`` (min, max) at each.
    """

    id: int
    name: str
    height_m: float
    skin: Color
    shirt: Color
    trousers: Color
    hair: Color
    speed_mps: float
    start_xy: XY
    goals: tuple[XY, ...] = ()
    start_goal: int = 0
    pause_s: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class CartSpec:
    """A cart that waits, then rolls to its next position at ``speed_mps`` (now and then)."""

    id: int
    name: str
    mesh: Mesh  # local frame, z up, centred on the origin footprint
    positions: tuple[XY, ...]
    yaw_rad: float
    speed_mps: float
    wait_s: tuple[float, float]


@dataclass
class World:
    name: str
    seed: int
    bounds: Rect
    ceiling_m: float
    objects: list[SimObject] = field(default_factory=list)
    walls: list[Rect] = field(default_factory=list)  # footprints of wall pieces
    obstacles: list[Rect] = field(default_factory=list)  # walls + furniture footprints
    walkers: list[WalkerSpec] = field(default_factory=list)
    carts: list[CartSpec] = field(default_factory=list)
    waypoints: list[XY] = field(default_factory=list)  # robot route, visited cyclically
    walkable: list[Rect] = field(default_factory=list)  # where random goals are drawn
    _next_id: int = 1

    def new_id(self) -> int:
        self._next_id += 1
        return self._next_id - 1

    def add(
        self,
        name: str,
        class_name: str,
        layer: str,
        mesh: Mesh,
        plane: tuple[float, float, float, float] | None = None,
        blocks: bool = False,
    ) -> SimObject:
        obj = SimObject(self.new_id(), name, class_name, layer, mesh, plane)
        self.objects.append(obj)
        if blocks:
            lo, hi = mesh.bounds()
            self.obstacles.append((float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])))
        return obj


class _Builder:
    """Helpers that add walls, floors and furniture to a world with seeded colours."""

    def __init__(self, world: World) -> None:
        self.w = world
        self.rng = np.random.default_rng(world.seed)
        self.count: dict[str, int] = {}

    def name(self, class_name: str) -> str:
        k = self.count.get(class_name, 0)
        self.count[class_name] = k + 1
        return f"{class_name.replace(' ', '_')}_{k}"

    def color(self, base: Color, spread: float = 0.08) -> Color:
        c = np.clip(np.asarray(base) + self.rng.uniform(-spread, spread, 3), 0.0, 1.0)
        return (float(c[0]), float(c[1]), float(c[2]))

    def floor_and_ceiling(self) -> None:
        x0, y0, x1, y1 = self.w.bounds
        r, g, b = self.color((0.66, 0.6, 0.5))
        tiles = ((r * 1.06, g * 1.06, b * 1.06), (r * 0.94, g * 0.94, b * 0.94))
        self.w.add(
            "floor_0",
            "floor",
            "background",
            checker_floor((x0, y0, -0.05), (x1, y1, 0.0), 0.5, tiles),
            plane=(0.0, 0.0, 1.0, 0.0),
        )
        h = self.w.ceiling_m
        self.w.add(
            "ceiling_0",
            "ceiling",
            "background",
            box((x0, y0, h), (x1, y1, h + 0.05), (0.93, 0.93, 0.9)),
            plane=(0.0, 0.0, -1.0, h),
        )

    def wall(
        self, a: XY, b: XY, doors: Sequence[tuple[float, float]] = (), color: Color | None = None
    ) -> None:
        """An axis-aligned wall from ``a`` to ``b`` with door gaps (offset of centre from a, width)."""
        t = WALL_THICKNESS_M / 2.0
        h = self.w.ceiling_m
        horizontal = abs(b[1] - a[1]) < 1e-9
        if not horizontal and abs(b[0] - a[0]) > 1e-9:
            raise ConfigError(f"wall {a}-{b}: only axis-aligned walls are supported")
        s0, s1 = (a[0], b[0]) if horizontal else (a[1], b[1])
        s0, s1 = min(s0, s1) - t, max(s0, s1) + t
        fixed = a[1] if horizontal else a[0]
        gaps = sorted(
            (min(a[0], b[0]) + off - wd / 2, min(a[0], b[0]) + off + wd / 2)
            if horizontal
            else (min(a[1], b[1]) + off - wd / 2, min(a[1], b[1]) + off + wd / 2)
            for off, wd in doors
        )
        spans, cur = [], s0
        for g0, g1 in gaps:
            spans.append((cur, g0, 0.0))
            spans.append((g0, g1, DOOR_HEIGHT_M))  # lintel above the door
            cur = g1
        spans.append((cur, s1, 0.0))
        col = color or self.color((0.86, 0.84, 0.78), 0.05)
        parts = []
        for p0, p1, z0 in spans:
            if p1 - p0 < 1e-6:
                continue
            lo = (p0, fixed - t, z0) if horizontal else (fixed - t, p0, z0)
            hi = (p1, fixed + t, h) if horizontal else (fixed + t, p1, h)
            parts.append(box(lo, hi, col))
            if z0 == 0.0:
                self.w.walls.append((lo[0], lo[1], hi[0], hi[1]))
                self.w.obstacles.append((lo[0], lo[1], hi[0], hi[1]))
        plane = (0.0, 1.0, 0.0, -fixed) if horizontal else (1.0, 0.0, 0.0, -fixed)
        self.w.add(self.name("wall"), "wall", "background", Mesh.concat(parts), plane=plane)

    def place(
        self,
        class_name: str,
        layer: str,
        mesh: Mesh,
        x: float,
        y: float,
        yaw_deg: float = 0.0,
        z: float = 0.0,
        blocks: bool = True,
        plane: tuple[float, float, float, float] | None = None,
    ) -> SimObject:
        T = rot_z(math.radians(yaw_deg), (x, y, z))
        return self.w.add(self.name(class_name), class_name, layer, mesh.transformed(T), plane, blocks)

    def on_wall(self, class_name: str, mesh: Mesh, x: float, y: float, facing_deg: float, z: float) -> None:
        """Hang a flat mesh (built facing +x, back at x = 0) on the wall face at (x, y)."""
        self.place(class_name, "foreground", mesh, x, y, facing_deg, z, blocks=False)

    def picture(self, x: float, y: float, facing_deg: float) -> None:
        w, h = float(self.rng.uniform(0.5, 0.7)), float(self.rng.uniform(0.7, 0.9))
        mesh = fu.framed_person(
            w, h, self.color((0.35, 0.22, 0.12)), self.color((0.8, 0.8, 0.7), 0.15), 0.85 * h, rng=self.rng
        )
        self.on_wall("picture", mesh, x, y, facing_deg, 1.5 - h / 2)

    def door(self, x: float, y: float, facing_deg: float) -> None:
        """A closed door panel on a wall face (background ``door``)."""
        mesh = Mesh.concat(
            [
                box((0.0, -0.45, 0.0), (0.02, 0.45, 2.05), self.color((0.55, 0.38, 0.2))),
                box((0.02, 0.3, 0.95), (0.07, 0.38, 1.0), (0.8, 0.8, 0.8)),
            ]
        )
        yaw = math.radians(facing_deg)
        nx, ny = math.cos(yaw), math.sin(yaw)
        d = -(nx * (x + 0.02 * nx) + ny * (y + 0.02 * ny))
        self.place(
            "door",
            "background",
            mesh,
            x,
            y,
            facing_deg,
            0.0,
            blocks=False,
            plane=(round(nx, 12), round(ny, 12), 0.0, d),
        )

    def table(
        self, x: float, y: float, length: float, width: float, yaw_deg: float = 0.0, height: float = 0.75
    ) -> None:
        mesh = fu.table(length, width, height, self.color((0.55, 0.4, 0.25)), self.color((0.3, 0.2, 0.12)))
        self.place("table", "background", mesh, x, y, yaw_deg, plane=(0.0, 0.0, 1.0, -height))

    def chair(self, x: float, y: float, facing_deg: float) -> None:
        mesh = fu.chair(self.color((0.6, 0.15, 0.1), 0.15), self.color((0.25, 0.15, 0.08)))
        self.place("chair", "foreground", mesh, x, y, facing_deg)

    def small_things(self, x0: float, y0: float, x1: float, y1: float, z: float, n: int) -> None:
        """``n`` bottles and cups on a surface, spaced apart."""
        placed: list[XY] = []
        for _ in range(n):
            for _try in range(30):
                p = (float(self.rng.uniform(x0 + 0.1, x1 - 0.1)), float(self.rng.uniform(y0 + 0.1, y1 - 0.1)))
                if all(math.dist(p, q) > 0.18 for q in placed):
                    break
            else:
                continue
            placed.append(p)
            if self.rng.random() < 0.55:
                glass = self.color(
                    [(0.1, 0.45, 0.15), (0.45, 0.25, 0.1), (0.2, 0.35, 0.7)][int(self.rng.integers(3))]
                )
                self.place(
                    "bottle",
                    "foreground",
                    fu.bottle(float(self.rng.uniform(0.22, 0.32)), glass),
                    p[0],
                    p[1],
                    0.0,
                    z,
                    blocks=False,
                )
            else:
                mug = self.color(
                    [(0.9, 0.9, 0.88), (0.8, 0.2, 0.15), (0.2, 0.3, 0.6)][int(self.rng.integers(3))]
                )
                self.place(
                    "cup",
                    "foreground",
                    fu.cup(mug),
                    p[0],
                    p[1],
                    float(self.rng.integers(4)) * 90.0,
                    z,
                    blocks=False,
                )

    def walker(
        self,
        name: str,
        speed_mps: float,
        start: XY,
        goals: Sequence[XY] = (),
        start_goal: int = 0,
        pause_s: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        shirts = [
            (0.75, 0.1, 0.1),
            (0.1, 0.3, 0.7),
            (0.9, 0.8, 0.2),
            (0.2, 0.6, 0.3),
            (0.95, 0.95, 0.95),
            (0.5, 0.2, 0.6),
        ]
        self.w.walkers.append(
            WalkerSpec(
                id=self.w.new_id(),
                name=name,
                height_m=float(self.rng.uniform(1.6, 1.9)),
                skin=SKIN_TONES[int(self.rng.integers(len(SKIN_TONES)))],
                shirt=self.color(shirts[int(self.rng.integers(len(shirts)))], 0.05),
                trousers=self.color((0.15, 0.18, 0.3), 0.1),
                hair=self.color((0.15, 0.1, 0.05), 0.05),
                speed_mps=speed_mps,
                start_xy=start,
                goals=tuple(goals),
                start_goal=start_goal,
                pause_s=pause_s,
            )
        )


def _house(seed: int) -> World:
    rng = np.random.default_rng(seed)
    W, D = 9.0 + float(rng.uniform(-0.4, 0.4)), 7.0 + float(rng.uniform(-0.3, 0.3))
    a, b = 4.8 + float(rng.uniform(-0.2, 0.2)), 3.4 + float(rng.uniform(-0.2, 0.2))
    w = World("house", seed, (0.0, 0.0, W, D), 2.6)
    B = _Builder(w)
    B.floor_and_ceiling()
    B.wall((0, 0), (W, 0))
    B.wall((W, 0), (W, D))
    B.wall((0, D), (W, D))
    B.wall((0, 0), (0, D))
    B.wall((a, 0), (a, D), doors=[(1.7, 0.9), (b + 0.8, 0.9)])
    B.wall((a, b), (W, b))
    # Living and dining room (x < a).
    tx, ty = 1.7, 1.9
    B.table(tx, ty, 1.6, 0.9)
    for dx in (-0.4, 0.4):
        B.chair(tx + dx, ty - 0.72, 90.0)
        B.chair(tx + dx, ty + 0.72, -90.0)
    B.small_things(tx - 0.7, ty - 0.35, tx + 0.7, ty + 0.35, 0.75, int(rng.integers(3, 6)))
    sofa_y = D - 1.2
    B.place(
        "couch",
        "foreground",
        fu.couch(2.0, B.color((0.3, 0.35, 0.5)), B.color((0.4, 0.45, 0.6))),
        0.5,
        sofa_y,
        0.0,
    )
    B.place(
        "shelf", "foreground", fu.shelf(0.9, 0.5, B.color((0.45, 0.3, 0.18)), B.rng), a - 0.2, sofa_y, 180.0
    )
    B.on_wall("tv", fu.tv(1.0, B.rng), a - 0.4, sofa_y, 180.0, 0.55)
    B.place("shelf", "foreground", fu.shelf(1.2, 1.8, B.color((0.45, 0.3, 0.18)), B.rng), 2.4, D - 0.2, -90.0)
    B.place("potted plant", "foreground", fu.plant(B.color((0.7, 0.35, 0.2))), 0.35, 0.35)
    B.picture(1.7, WALL_THICKNESS_M / 2, 90.0)
    B.picture(WALL_THICKNESS_M / 2, 3.6, 0.0)
    B.door(0.9, D - WALL_THICKNESS_M / 2, -90.0)
    # Study (x > a, y < b).
    B.table(W - 0.45, 1.6, 1.2, 0.6, 90.0, 0.74)
    B.chair(W - 1.1, 1.6, 0.0)
    B.small_things(W - 0.7, 1.1, W - 0.2, 2.1, 0.74, int(rng.integers(2, 4)))
    B.place("shelf", "foreground", fu.shelf(1.0, 1.4, B.color((0.5, 0.35, 0.2)), B.rng), a + 1.4, 0.2, 90.0)
    B.place("potted plant", "foreground", fu.plant(B.color((0.3, 0.3, 0.7))), W - 0.35, b - 0.35)
    # Bedroom (x > a, y > b).
    B.place(
        "bed",
        "foreground",
        fu.bed(2.0, 1.4, B.color((0.4, 0.28, 0.16)), B.color((0.5, 0.6, 0.8)), (0.95, 0.95, 0.95)),
        W - 1.08,
        (b + D) / 2,
        180.0,
    )
    B.picture(W - WALL_THICKNESS_M / 2, (b + D) / 2 + 1.1, 180.0)
    B.place(
        "shelf", "foreground", fu.shelf(0.8, 1.2, B.color((0.6, 0.5, 0.4)), B.rng), a + 0.8, D - 0.2, -90.0
    )
    B.door(W - 0.8, D - WALL_THICKNESS_M / 2, -90.0)
    # Diagonal legs look across the rooms at the furniture.
    w.waypoints = [
        (3.9, D - 0.8),
        (2.7, 3.6),
        (3.9, 1.0),
        (a + 1.2, 1.7),
        (W - 1.6, b - 0.9),
        (a - 1.0, 1.7),
        (2.4, 4.6),
        (3.6, b + 0.8),
        (a + 1.0, b + 0.8),
        (a + 1.4, D - 0.9),
        (a - 0.6, b + 0.8),
        (1.6, 4.4),
    ]
    w.walkable = [
        (0.6, 0.6, a - 0.6, D - 0.6),
        (a + 0.6, 0.6, W - 0.6, b - 0.6),
        (a + 0.6, b + 0.6, W - 0.6, D - 0.6),
    ]
    B.walker("person_0", 0.9, (3.5, 3.2), pause_s=(1.0, 4.0))
    return w


def _hospital(seed: int) -> World:
    rng = np.random.default_rng(seed)
    L = 24.0
    cw = 2.6 + float(rng.uniform(-0.1, 0.1))  # corridor width
    band = 4.0
    H = 2 * cw + band
    w = World("hospital", seed, (0.0, 0.0, L, H), 2.8)
    B = _Builder(w)
    B.floor_and_ceiling()
    B.wall((0, 0), (L, 0))
    B.wall((L, 0), (L, H))
    B.wall((0, H), (L, H))
    B.wall((0, 0), (0, H))
    end = 2.4
    room_w = (L - 2 * end) / 4
    B.wall((end, cw), (L - end, cw), doors=[(k * room_w + 1.0, 1.1) for k in range(4)])
    B.wall((end, cw + band), (L - end, cw + band))
    for k in range(5):
        B.wall((end + k * room_w, cw), (end + k * room_w, cw + band))
    for k in range(4):
        x0 = end + k * room_w
        B.place(
            "bed",
            "foreground",
            fu.bed(2.0, 1.0, (0.8, 0.8, 0.82), B.color((0.6, 0.75, 0.85)), (0.95, 0.95, 0.95)),
            x0 + room_w - 1.05 - WALL_THICKNESS_M / 2,  # head board against the wall's face
            cw + band / 2,
            180.0,
        )
        B.chair(x0 + room_w - 2.6, cw + band / 2 + 1.2, -90.0)
        B.table(x0 + 0.5, cw + band - 0.5, 0.6, 0.6, 0.0, 0.8)
        B.small_things(x0 + 0.25, cw + band - 0.75, x0 + 0.75, cw + band - 0.25, 0.8, 2)
        B.picture(x0 + room_w / 2, cw + band - WALL_THICKNESS_M / 2, -90.0)
        B.door(x0 + room_w / 2, cw + band + WALL_THICKNESS_M / 2, 90.0)
    for x in (6.0, 14.0, 20.0):
        B.picture(x, WALL_THICKNESS_M / 2, 90.0)
    B.place("potted plant", "foreground", fu.plant(B.color((0.6, 0.6, 0.6))), 0.4, 0.4)
    B.place("potted plant", "foreground", fu.plant(B.color((0.6, 0.6, 0.6))), L - 0.4, H - 0.4)
    cart_y = 0.4
    w.carts.append(
        CartSpec(
            w.new_id(),
            "cart_0",
            fu.cart(B.rng),
            ((5.0, cart_y), (11.0, cart_y), (18.0, cart_y)),
            0.0,
            0.5,
            (15.0, 30.0),
        )
    )
    # Five people walking between predefined positions of corridor A; corridor B stays empty.
    lanes = [0.9, 1.3, 1.7, 1.1, 1.5]
    stops_x = [3.2, 8.0, 12.5, 16.5, L - 3.2]
    for i in range(5):
        y = lanes[i] + (cw - 2.6) / 2
        goals = [(stops_x[0], y), (stops_x[(i % 3) + 1], y), (stops_x[4], y), (stops_x[((i + 1) % 3) + 1], y)]
        start = (float(stops_x[0] + (stops_x[4] - stops_x[0]) * (i + 0.5) / 5.0), y)
        B.walker(f"person_{i}", 0.6, start, goals, start_goal=(i % 2) * 2)
    mid = cw + band / 2
    w.waypoints = [
        (1.2, cw / 2),
        (end + 1.0, cw / 2),
        (end + 1.6, mid - 0.6),
        (end + 1.0, cw / 2),
        (L / 2, cw / 2),
        (L / 2 + 1.0, mid - 0.4),
        (L / 2 + 0.4, cw / 2),
        (L - 1.2, cw / 2),
        (L - 1.2, H - cw / 2),
        (1.2, H - cw / 2),
    ]
    w.walkable = [(0.6, 0.6, L - 0.6, cw - 0.6)]
    return w


def _office(seed: int) -> World:
    rng = np.random.default_rng(seed)
    W, D = 16.0, 10.6
    c0 = 4.0 + float(rng.uniform(-0.2, 0.2))
    c1 = c0 + 2.2
    w = World("office", seed, (0.0, 0.0, W, D), 2.7)
    B = _Builder(w)
    B.floor_and_ceiling()
    B.wall((0, 0), (W, 0))
    B.wall((W, 0), (W, D))
    B.wall((0, D), (W, D))
    B.wall((0, 0), (0, D))
    B.wall((0, c0), (W, c0), doors=[(2.0, 1.0), (11.0, 1.0)])
    B.wall((8.0, 0), (8.0, c0))
    B.wall((7.0, c1), (W, c1), doors=[(3.0, 1.0)])
    B.wall((7.0, c1), (7.0, D))
    # Lab (x < 8, y < c0): desks along the south wall with bottles, chairs, a shelf.
    for k, x in enumerate((1.6, 4.0, 6.4)):
        B.table(x, 0.45, 1.6, 0.7, 0.0, 0.76)
        B.chair(x, 1.25, -90.0)
        B.small_things(x - 0.7, 0.2, x + 0.7, 0.7, 0.76, int(rng.integers(2, 5)) + (k == 1))
    B.table(4.0, c0 - 1.3, 2.0, 0.8, 0.0, 0.9)
    B.small_things(3.2, c0 - 1.6, 4.8, c0 - 1.0, 0.9, int(rng.integers(3, 6)))
    B.place("shelf", "foreground", fu.shelf(1.2, 1.8, B.color((0.6, 0.6, 0.62)), B.rng), 7.75, 2.2, 180.0)
    # Office (x > 8, y < c0).
    for x in (10.0, 13.5):
        B.table(x, 0.45, 1.4, 0.7, 0.0, 0.74)
        B.chair(x, 1.2, -90.0)
        B.small_things(x - 0.6, 0.2, x + 0.6, 0.7, 0.74, 2)
    B.place("potted plant", "foreground", fu.plant(B.color((0.8, 0.8, 0.8))), W - 0.4, c0 - 0.4)
    B.picture(W - WALL_THICKNESS_M / 2, 2.0, 180.0)
    # Stairwell-like open area (x < 7, y > c1), open to the corridor.
    B.place("stairs", "background", fu.stairs(9, 1.3, B.color((0.7, 0.7, 0.72))), 1.0, D - 0.75, 0.0)
    B.place("potted plant", "foreground", fu.plant(B.color((0.5, 0.3, 0.2))), 6.5, D - 0.4)
    B.picture(WALL_THICKNESS_M / 2, c1 + 1.5, 0.0)
    B.place(
        "couch",
        "foreground",
        fu.couch(1.8, B.color((0.55, 0.15, 0.15)), B.color((0.65, 0.2, 0.2))),
        6.45,
        c1 + 1.6,
        180.0,
    )
    # Meeting room (x > 7, y > c1): table, chairs, a TV.
    my = (c1 + D) / 2
    B.table(11.5, my, 2.4, 1.0)
    for dx in (-0.7, 0.0, 0.7):
        B.chair(11.5 + dx, my - 0.78, 90.0)
        B.chair(11.5 + dx, my + 0.78, -90.0)
    B.small_things(10.5, my - 0.4, 12.5, my + 0.4, 0.75, int(rng.integers(2, 5)))
    B.on_wall("tv", fu.tv(1.2, B.rng), W - WALL_THICKNESS_M / 2, my, 180.0, 0.9)
    B.door(W - 1.0, c1 - WALL_THICKNESS_M / 2, -90.0)
    cy = (c0 + c1) / 2
    w.waypoints = [
        (1.2, cy),
        (3.5, c1 + 1.0),
        (2.0, cy),
        (2.0, c0 - 0.5),
        (5.5, 1.9),
        (2.0, c0 - 0.6),
        (11.0, cy),
        (11.0, c0 - 0.6),
        (13.5, 2.2),
        (11.0, c0 - 0.7),
        (10.0, cy),
        (10.0, c1 + 0.6),
        (14.5, my),
        (10.0, c1 + 0.5),
        (W - 1.0, cy),
    ]
    w.walkable = [
        (0.6, c0 + 0.5, W - 0.6, c1 - 0.5),
        (0.6, c1 + 0.5, 5.0, D - 1.6),
        (0.8, 1.8, 7.2, c0 - 1.9),
    ]
    B.walker("person_0", 1.0, (W - 2.0, cy), pause_s=(1.0, 5.0))
    B.walker("person_1", 0.8, (4.0, c1 + 1.0), pause_s=(2.0, 6.0))
    return w


WORLDS: dict[str, Callable[[int], World]] = {"house": _house, "hospital": _hospital, "office": _office}


def make_world(name: str, seed: int) -> World:
    """Build the preset ``name`` (house, hospital, office) for ``seed``."""
    try:
        factory = WORLDS[name]
    except KeyError:
        raise ConfigError(f"unknown world {name!r}; expected one of {', '.join(WORLDS)}") from None
    return factory(seed)
