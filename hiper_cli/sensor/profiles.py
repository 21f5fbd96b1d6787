"""Sensor profiles: the artefacts of a real RGB-D camera on a robot, as named parameters.

A profile turns an ideal frame (exact depth, colour registered to depth, exact pose) into what
a real sensor of that kind delivers. Every value below is named after what it models and comes
from a datasheet or a published noise model:

structured-light (Kinect v1 / Asus Xtion):
  range 0.45-5.0 m [KE12: 0.5-5 m]; axial σ_z = 0.0012 + 0.0019 (z - 0.4)² m [N12, 10-60° incidence];
  disparity quantised to 1/8 px with f = 585.6 px, b = 0.075 m [KE12]; projector 0.075 m along +x
  casts shadows [KE12]; 30 % of edge pixels (a step > 10 % of the depth) fly; dropouts: dark
  (luma < 20) 50 %, glossy (luma > 250) 60 %, incidence > 75° [KE12, N12]; colour shifted 3, 2 px
  against depth [SP11: factory registration off by a few px]; rolling shutter 30 ms, exposure 15 ms;
  JPEG 75 (a compressed image topic).
tof (Kinect v2 / Azure Kinect):
  range 0.5-4.5 m [MS]; σ_z = 0.0015 - 0.0005 z + 0.0003 z² m [F15]; no quantisation (phase) and
  no shadows (emitter beside the lens); 90 % of edge pixels fly (mixed phase, multipath) [F15];
  dark 70 %, glossy 60 %, incidence > 70° [F15]; colour 2, 1 px; 20 ms readout, 10 ms exposure; JPEG 80.
stereo (RealSense D435, active IR stereo):
  range 0.28-6.0 m [D4: min-Z 0.28 m at 640×480]; 0.08 px disparity noise, so σ_z = 0.08 z² / (f b),
  with f = 382 px, b = 0.050 m and 1/32 px quantisation [D4]; the second imager 0.050 m along +x
  cannot see behind near edges (shadows); 50 % of edge pixels fly (the matching window straddles the
  edge); dark/textureless 40 %, glossy 50 %, incidence > 75°; colour 1, 1 px; 15 ms readout, 8 ms
  exposure; JPEG 80.
Pose source (all but ideal): 4 mm and 0.15° of noise, drift 0.5 % of the distance and 0.1°/m
  (ORB-SLAM2 reaches ~1 % RMSE on TUM RGB-D sequences) - see ``hiper_cli.sensor.poses``.

Sources: [KE12] Khoshelham & Elberink, "Accuracy and Resolution of Kinect Depth Data for Indoor
Mapping Applications", Sensors 12(2), 2012. [N12] Nguyen, Izadi & Lovell, "Modeling Kinect Sensor
Noise for Improved 3D Reconstruction and Tracking", 3DIMPVT 2012. [F15] Fankhauser et al.,
"Kinect v2 for Mobile Robot Navigation: Evaluation and Modeling", ICAR 2015. [D4] Intel RealSense
D400 datasheet and "Tuning depth cameras for best performance" (RMS error = z² × subpixel / (f × b)).
[SP11] Smisek, Jancosek & Pajdla, "3D with Kinect", ICCV workshops 2011. [MS] Microsoft Kinect v2
specification. ORB-SLAM2: Mur-Artal & Tardós, T-RO 2017.

``ideal`` turns everything off: the output equals the input (up to the file format).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any

from hiper_cli.errors import ConfigError

__all__ = ["PROFILES", "SensorProfile", "get_profile"]


@dataclass(frozen=True)
class SensorProfile:
    """One sensor's artefacts; see the module docstring for every value's source.

    Depth noise: σ_z(z) = noise_c0_m + noise_c1 z + noise_c2_per_m z² (metres), plus, for
    disparity sensors, ``disparity_sigma_px`` of Gaussian noise in disparity; depth is then
    quantised to ``disparity_step_px`` of disparity at ``disparity_focal_px`` × ``baseline_m``.
    """

    name: str
    summary: str
    min_range_m: float = 0.0
    max_range_m: float = float("inf")
    noise_c0_m: float = 0.0
    noise_c1: float = 0.0
    noise_c2_per_m: float = 0.0
    disparity_sigma_px: float = 0.0
    disparity_focal_px: float = 0.0
    disparity_step_px: float = 0.0
    baseline_m: float = 0.0
    shadows: bool = False
    flying_fraction: float = 0.0
    edge_jump_frac: float = 0.10
    dark_luma: float = 20.0
    dark_dropout: float = 0.0
    glossy_luma: float = 250.0
    glossy_dropout: float = 0.0
    grazing_deg: float = 90.0
    dropout_block_px: int = 4
    misregistration_px: tuple[float, float] = (0.0, 0.0)
    readout_s: float = 0.0
    exposure_s: float = 0.0
    jpeg_quality: int = 0
    pose_noise_m: float = 0.0
    pose_noise_deg: float = 0.0
    drift_per_m: float = 0.0
    drift_deg_per_m: float = 0.0

    def __post_init__(self) -> None:
        for key in ("flying_fraction", "dark_dropout", "glossy_dropout"):
            if not 0.0 <= getattr(self, key) <= 1.0:
                raise ConfigError(f"sensor {self.name}: {key}={getattr(self, key)}; expected 0 to 1")
        if not 0 <= self.jpeg_quality <= 100:
            raise ConfigError(f"sensor {self.name}: jpeg_quality={self.jpeg_quality}; "
                              "expected 0 (off) to 100")
        if self.drift_per_m < 0 or self.pose_noise_m < 0:
            raise ConfigError(f"sensor {self.name}: pose drift and noise must be >= 0")

    @property
    def quantised(self) -> bool:
        return self.disparity_step_px > 0 and self.disparity_focal_px > 0 and self.baseline_m > 0

    @property
    def exact_poses(self) -> bool:
        return self.pose_noise_m == 0 and self.pose_noise_deg == 0 and self.drift_per_m == 0 \
            and self.drift_deg_per_m == 0

    def with_pose_drift(self, drift_per_m: float) -> SensorProfile:
        """This profile with translation drift ``drift_per_m`` (m per m travelled); rotation drift
        and pose noise scale with it, and 0 gives the exact poses."""
        if drift_per_m < 0:
            raise ConfigError(f"--pose-drift {drift_per_m}: expected metres of drift per metre "
                              "travelled, >= 0 (0.005 = 0.5 %)")
        scale = drift_per_m / self.drift_per_m if self.drift_per_m > 0 else (1.0 if drift_per_m > 0 else 0.0)
        return replace(self, drift_per_m=drift_per_m, drift_deg_per_m=self.drift_deg_per_m * scale,
                       pose_noise_m=self.pose_noise_m * scale, pose_noise_deg=self.pose_noise_deg * scale)

    def to_dict(self) -> dict[str, Any]:
        out = asdict(self)
        out["misregistration_px"] = list(self.misregistration_px)
        if out["max_range_m"] == float("inf"):
            out["max_range_m"] = None
        return out


_POSE: dict[str, Any] = {"pose_noise_m": 0.004, "pose_noise_deg": 0.15, "drift_per_m": 0.005,
                         "drift_deg_per_m": 0.1}

PROFILES: dict[str, SensorProfile] = {
    "ideal": SensorProfile("ideal", "no artefacts: the log as it is"),
    "structured-light": SensorProfile(
        "structured-light", "Kinect v1 / Asus Xtion: projector shadows, disparity steps, dropouts",
        min_range_m=0.45, max_range_m=5.0, noise_c0_m=0.0012 + 0.0019 * 0.16, noise_c1=-0.0019 * 0.8,
        noise_c2_per_m=0.0019, disparity_focal_px=585.6, disparity_step_px=1 / 8, baseline_m=0.075,
        shadows=True, flying_fraction=0.3, dark_dropout=0.5, glossy_dropout=0.6, grazing_deg=75.0,
        misregistration_px=(3.0, 2.0), readout_s=0.030, exposure_s=0.015, jpeg_quality=75, **_POSE),
    "tof": SensorProfile(
        "tof", "Kinect v2 / Azure Kinect: flying pixels, dark-surface dropouts, no shadows",
        min_range_m=0.5, max_range_m=4.5, noise_c0_m=0.0015, noise_c1=-0.0005, noise_c2_per_m=0.0003,
        flying_fraction=0.9, dark_dropout=0.7, glossy_dropout=0.6, grazing_deg=70.0,
        misregistration_px=(2.0, 1.0), readout_s=0.020, exposure_s=0.010, jpeg_quality=80, **_POSE),
    "stereo": SensorProfile(
        "stereo", "RealSense D435: disparity noise growing with z², occlusion shadows, textureless holes",
        min_range_m=0.28, max_range_m=6.0, disparity_sigma_px=0.08, disparity_focal_px=382.0,
        disparity_step_px=1 / 32, baseline_m=0.050, shadows=True, flying_fraction=0.5, dark_dropout=0.4,
        glossy_dropout=0.5, grazing_deg=75.0, misregistration_px=(1.0, 1.0), readout_s=0.015,
        exposure_s=0.008, jpeg_quality=80, **_POSE),
}


def get_profile(name: str) -> SensorProfile:
    """The profile called ``name``; an unknown name lists the known ones."""
    try:
        return PROFILES[name]
    except KeyError:
        known = ", ".join(PROFILES)
        raise ConfigError(f"sensor profile {name!r}: unknown; expected one of {known}") from None
