"""Ray-cast RGB, depth and per-pixel instance ids with open3d's ``RaycastingScene``.

One ray per pixel of a pinhole camera: pixel (u, v) (integers) looks along
``((u - cx) / fx, (v - cy) / fy, 1)`` in the optical frame, so the hit distance along that
unnormalised ray is the depth z. Depth gets the axial noise of a structured-light sensor,
sigma(z) = a + b·(z - z0)² (Nguyen, Izadi and Lovell 2012, Kinect: a = 1.2 mm, b = 1.9 mm/m²,
z0 = 0.4 m), is quantised to the TUM depth unit and is 0 (no return) below the minimum and
beyond the maximum range; instance ids are 0 wherever depth is 0. RGB is the triangle colour
with Lambert shading from a head light and a ceiling light.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError
from hiper_cli.sim.meshes import Mesh
from hiper_cli.types import CameraIntrinsics

__all__ = ["DepthNoise", "RenderConfig", "RenderOutput", "Renderer", "camera_for"]


@dataclass(frozen=True)
class DepthNoise:
    """Axial depth noise sigma(z) = a_m + b_per_m · (z - z0_m)² (metres); zero a and b turn it off."""

    a_m: float = 0.0012
    b_per_m: float = 0.0019
    z0_m: float = 0.4

    def sigma_m(self, z_m: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.a_m + self.b_per_m * (z_m - self.z0_m) ** 2

    @property
    def enabled(self) -> bool:
        return self.a_m > 0.0 or self.b_per_m > 0.0


@dataclass(frozen=True)
class RenderConfig:
    """Image size, sensor range (the paper's sensor sees 5 m) and depth noise."""

    width: int = 640
    height: int = 480
    focal_px_at_640: float = 525.0
    max_range_m: float = 5.0
    min_range_m: float = 0.3
    noise: DepthNoise = DepthNoise()
    depth_scale: float = 5000.0

    def __post_init__(self) -> None:
        if self.width < 16 or self.height < 16:
            raise ConfigError(f"image {self.width}×{self.height}: expected at least 16×16 pixels")
        if not 0 < self.min_range_m < self.max_range_m:
            raise ConfigError(f"range {self.min_range_m}-{self.max_range_m} m: expected 0 < min < max")


def camera_for(config: RenderConfig) -> CameraIntrinsics:
    f = config.focal_px_at_640 * config.width / 640.0
    return CameraIntrinsics(
        width=config.width,
        height=config.height,
        fx=f,
        fy=f,
        cx=(config.width - 1) / 2.0,
        cy=(config.height - 1) / 2.0,
        depth_scale=config.depth_scale,
    )


@dataclass(frozen=True)
class RenderOutput:
    rgb: NDArray[np.uint8]  # (H, W, 3) RGB
    depth_m: NDArray[np.float32]  # (H, W), 0 = no return
    ids: NDArray[np.uint16]  # (H, W), 0 = no return


class Renderer:
    """Holds the static meshes; ``render`` adds the moving ones for one camera pose."""

    def __init__(self, static: Sequence[tuple[int, Mesh]], config: RenderConfig | None = None) -> None:
        self.cfg = config or RenderConfig()
        self.camera = camera_for(self.cfg)
        self.static = list(static)
        cam = self.camera
        u, v = np.meshgrid(np.arange(cam.width), np.arange(cam.height))
        self._dirs_cam = np.stack(
            [(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, np.ones(u.shape)], axis=-1
        ).reshape(-1, 3)
        self._norm = np.linalg.norm(self._dirs_cam, axis=1)
        light = np.array([0.3, 0.2, 1.0])
        self._light = light / np.linalg.norm(light)

    def render(
        self, T_map_cam: NDArray[np.float64], dynamic: Sequence[tuple[int, Mesh]], rng: np.random.Generator
    ) -> RenderOutput:
        import open3d as o3d

        scene = o3d.t.geometry.RaycastingScene()
        items = [*self.static, *dynamic]
        ids = np.zeros(len(items) + 1, dtype=np.uint16)
        offsets = np.zeros(len(items) + 1, dtype=np.int64)
        colors = []
        total = 0
        for inst_id, mesh in items:
            gid = scene.add_triangles(
                _tensor(mesh.vertices.astype(np.float32)), _tensor(mesh.triangles.astype(np.uint32))
            )
            ids[gid] = inst_id
            offsets[gid] = total
            total += len(mesh.triangles)
            colors.append(mesh.colors)
        all_colors = np.concatenate(colors) if colors else np.zeros((0, 3))
        R, t = T_map_cam[:3, :3], T_map_cam[:3, 3]
        dirs = self._dirs_cam @ R.T
        rays = np.concatenate([np.broadcast_to(t, dirs.shape), dirs], axis=1).astype(np.float32)
        hit = scene.cast_rays(_tensor(rays))
        t_hit = hit["t_hit"].numpy().astype(np.float64)
        gids = hit["geometry_ids"].numpy().astype(np.int64)
        prims = hit["primitive_ids"].numpy().astype(np.int64)
        normals = hit["primitive_normals"].numpy().astype(np.float64)
        ok = np.isfinite(t_hit)
        shape = (self.camera.height, self.camera.width)

        rgb = np.zeros((len(t_hit), 3))
        idx = offsets[np.where(ok, gids, 0)] + np.where(ok, prims, 0)
        base = all_colors[np.clip(idx, 0, max(len(all_colors) - 1, 0))] if len(all_colors) else rgb
        unit = dirs / self._norm[:, None]
        head = np.abs(np.einsum("ij,ij->i", normals, unit))
        top = np.abs(normals @ self._light)
        shade = 0.3 + 0.5 * head + 0.25 * top
        rgb = np.where(ok[:, None], base * shade[:, None], 0.0)
        rgb_u8 = np.clip(rgb * 255.0 + 0.5, 0, 255).astype(np.uint8).reshape(*shape, 3)

        z = np.where(ok, t_hit, 0.0)
        valid = ok & (z >= self.cfg.min_range_m) & (z <= self.cfg.max_range_m)
        if self.cfg.noise.enabled:
            z = z + rng.standard_normal(z.shape) * self.cfg.noise.sigma_m(z)
        z = np.round(z * self.cfg.depth_scale) / self.cfg.depth_scale
        valid &= z > 0
        depth = np.where(valid, z, 0.0).astype(np.float32).reshape(shape)
        inst = np.where(valid, ids[np.where(ok, gids, len(items))], 0).astype(np.uint16).reshape(shape)
        return RenderOutput(rgb_u8, depth, inst)


def _tensor(array: NDArray[Any]) -> Any:
    import open3d as o3d

    return o3d.core.Tensor(array)  # type: ignore[call-overload]
