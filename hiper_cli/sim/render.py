"""Ray-cast RGB, depth and per-pixel instance ids with open3d's ``RaycastingScene``.

One ray per pixel of a pinhole camera: pixel (u, v) (integers) looks along
``((u - cx) / fx, (v - cy) / fy, 1)`` in the optical frame, so the hit distance along that
unnormalised ray is the depth z. Depth gets the axial noise of a structured-light sensor,
sigma(z) = a + b·(z - z0)² (Nguyen, Izadi and Lovell 2012, Kinect: a = 1.2 mm, b = 1.9 mm/m²,
z0 = 0.4 m), is quantised in disparity (1/8 pixel, like a Kinect) and to the TUM depth
unit, and is 0 (no return) below the minimum and beyond the maximum range; instance ids
are 0 wherever depth is 0. RGB is the triangle colour with Lambert shading from a head
light and a ceiling light.
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
    """Axial depth noise sigma(z) = a_m + b_per_m · (z - z0_m)² (metres), then disparity quantisation.

    A structured-light sensor measures disparity d = fb / z in steps of ``disparity_step_px``
    (Kinect: 1/8 pixel, fb = 580 px × 0.075 m = 43.5 px·m), so depth comes in steps that
    grow as z² (1.1 cm at 2 m, 4.6 cm at 4 m). ``DepthNoise.off()`` gives exact depth.
    """

    a_m: float = 0.0012
    b_per_m: float = 0.0019
    z0_m: float = 0.4
    disparity_step_px: float = 0.125
    focal_baseline_px_m: float = 43.5

    @classmethod
    def off(cls) -> DepthNoise:
        return cls(0.0, 0.0, 0.4, 0.0)

    def sigma_m(self, z_m: NDArray[Any]) -> NDArray[Any]:
        return self.a_m + self.b_per_m * (z_m - self.z0_m) ** 2

    @property
    def enabled(self) -> bool:
        return self.a_m > 0.0 or self.b_per_m > 0.0

    def quantise(self, z_m: NDArray[np.float32]) -> NDArray[np.float32]:
        """Depth rounded to the nearest disparity step (unchanged when the step is 0)."""
        if self.disparity_step_px <= 0:
            return z_m
        fb = self.focal_baseline_px_m
        with np.errstate(divide="ignore"):
            d = np.round(fb / z_m / self.disparity_step_px) * self.disparity_step_px
            return np.where((z_m > 0) & (d > 0), fb / np.maximum(d, 1e-9), 0.0).astype(np.float32)


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
    # the exact surface, for the scorer's truth (``scene_truth.py``): noise-free depth (0 = no
    # hit, whatever the range), the id of every hit and its surface normal in the camera frame
    true_z_m: NDArray[np.float32]  # (H, W)
    hit_ids: NDArray[np.uint16]  # (H, W)
    normal_cam: NDArray[np.float32]  # (H, W, 3), unit


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
        self._dirs_cam = self._dirs_cam.astype(np.float32)
        self._unit_cam = self._dirs_cam / np.linalg.norm(self._dirs_cam, axis=1, keepdims=True)
        self._static_tensors: list[tuple[Any, Any]] | None = None
        light = np.array([0.3, 0.2, 1.0])
        self._light = light / np.linalg.norm(light)

    def render(
        self, T_map_cam: NDArray[np.float64], dynamic: Sequence[tuple[int, Mesh]], rng: np.random.Generator
    ) -> RenderOutput:
        import open3d as o3d

        if self._static_tensors is None:
            self._static_tensors = [
                (_tensor(m.vertices.astype(np.float32)), _tensor(m.triangles.astype(np.uint32)))
                for _, m in self.static
            ]
        scene = o3d.t.geometry.RaycastingScene()
        items = [*self.static, *dynamic]
        tensors = self._static_tensors + [
            (_tensor(m.vertices.astype(np.float32)), _tensor(m.triangles.astype(np.uint32)))
            for _, m in dynamic
        ]
        ids = np.zeros(len(items) + 1, dtype=np.uint16)  # the last entry: no hit
        offsets = np.zeros(len(items) + 1, dtype=np.int64)
        total = 0
        for (inst_id, mesh), (verts, tris) in zip(items, tensors, strict=True):
            gid = scene.add_triangles(verts, tris)
            ids[gid] = inst_id
            offsets[gid] = total
            total += len(mesh.triangles)
        offsets[len(items)] = total
        # one black colour row at the end for rays that hit nothing
        all_colors = np.concatenate([*(m.colors for _, m in items), np.zeros((1, 3))]).astype(np.float32)
        R = T_map_cam[:3, :3].astype(np.float32)
        dirs = _matmul3(self._dirs_cam, R.T)
        rays = np.empty((len(dirs), 6), dtype=np.float32)
        rays[:, :3] = T_map_cam[:3, 3]
        rays[:, 3:] = dirs
        hit = scene.cast_rays(_tensor(rays))
        t_hit = hit["t_hit"].numpy()
        ok = np.isfinite(t_hit)
        gids = np.where(ok, hit["geometry_ids"].numpy(), len(items)).astype(np.int64)
        prims = np.where(ok, hit["primitive_ids"].numpy(), 0).astype(np.int64)
        n_cam = _matmul3(hit["primitive_normals"].numpy(), R)  # normals in the camera frame
        shape = (self.camera.height, self.camera.width)

        base = all_colors[offsets[gids] + prims]
        head = np.abs(np.einsum("ij,ij->i", n_cam, self._unit_cam))
        top = np.abs(n_cam @ (R.T @ self._light).astype(np.float32))
        shade = (0.3 + 0.5 * head + 0.25 * top) * 255.0
        rgb_u8 = np.minimum(base * shade[:, None] + 0.5, 255.0).astype(np.uint8).reshape(*shape, 3)

        z: NDArray[np.float32] = np.where(ok, t_hit, 0.0).astype(np.float32)
        true_z = z.reshape(shape).copy()
        valid = ok & (z >= self.cfg.min_range_m) & (z <= self.cfg.max_range_m)
        if self.cfg.noise.enabled:
            sigma = self.cfg.noise.sigma_m(z).astype(np.float32)
            z = (z + rng.standard_normal(z.shape, dtype=np.float32) * sigma).astype(np.float32)
        z = self.cfg.noise.quantise(z)
        z = (np.round(z * self.cfg.depth_scale) / self.cfg.depth_scale).astype(np.float32)
        valid &= z > 0
        depth = np.where(valid, z, np.float32(0.0)).astype(np.float32).reshape(shape)
        hit_ids = ids[gids].astype(np.uint16)
        inst = np.where(valid, hit_ids, 0).astype(np.uint16).reshape(shape)
        return RenderOutput(rgb_u8, depth, inst, true_z, hit_ids.reshape(shape), n_cam.reshape(*shape, 3))


def _tensor(array: NDArray[Any]) -> Any:
    import open3d as o3d

    return o3d.core.Tensor(array)  # type: ignore[call-overload]


def _matmul3(a: NDArray[np.float32], M: NDArray[np.float32]) -> NDArray[np.float32]:
    """``a @ M`` for (N, 3) × (3, 3); numpy's matmul is slow for such thin matrices."""
    out: NDArray[np.float32] = a[:, 0:1] * M[0] + a[:, 1:2] * M[1] + a[:, 2:3] * M[2]
    out = out.astype(np.float32, copy=False)
    return out
