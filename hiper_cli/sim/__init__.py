"""Synthetic long-term RGB-D logs with ground truth (``hiper sim``).

    from hiper_cli.sim import simulate, SimConfig
    result = simulate("hospital", seconds=60, seed=1, out="out/hospital")

Worlds (``worlds``), people by the Social Force Model (``people``), the robot route
(``route``), ray-cast rendering (``render``), the truth detector's noise (``noise``) and
the writer (``writer``); the ground-truth format is specified in ``truth``.
"""

from hiper_cli.perceive.logs.truth import Truth, load_truth
from hiper_cli.sim.noise import NoiseModel
from hiper_cli.sim.people import SocialForceConfig
from hiper_cli.sim.render import DepthNoise, RenderConfig
from hiper_cli.sim.route import RouteConfig
from hiper_cli.sim.worlds import WORLDS, make_world
from hiper_cli.sim.writer import SimConfig, SimResult, simulate

__all__ = [
    "WORLDS",
    "DepthNoise",
    "NoiseModel",
    "RenderConfig",
    "RouteConfig",
    "SimConfig",
    "SimResult",
    "SocialForceConfig",
    "Truth",
    "load_truth",
    "make_world",
    "simulate",
]
