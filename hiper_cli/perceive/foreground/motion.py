"""How a track moves: the ``MotionModel`` protocol and the constant-velocity Kalman filter.

A motion model holds one track's state ``x`` = [x, y, z, vx, vy, vz] (map frame, m and m/s)
and its covariance ``P``. The tracker predicts it to each frame's stamp with white
acceleration noise of variance ``q`` (``q_vertical`` along z), updates it with observed
centres, and shrinks its velocity while the track goes unseen. Models are chosen by name
(``ForegroundConfig.motion_model``) from ``MOTION_MODELS``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from hiper_cli.errors import ConfigError

__all__ = ["MOTION_MODELS", "ConstantVelocityKF", "MotionModel", "make_motion_model", "process_noise",
           "transition"]

FloatArray = NDArray[np.float64]


class MotionModel(Protocol):
    """One track's state estimate; see the module docstring."""

    @property
    def x(self) -> FloatArray:
        """The state [x, y, z, vx, vy, vz] as a (6,) array (a view: do not write to it)."""
        ...

    @property
    def P(self) -> FloatArray:
        """The (6, 6) state covariance."""
        ...

    def predict(self, dt_s: float, q: float, q_vertical: float) -> None:
        """Advance the state by ``dt_s`` seconds."""
        ...

    def update(self, center_map_m: FloatArray) -> None:
        """Fuse one observed centre (3,)."""
        ...

    def reset(self, x: FloatArray, P: FloatArray) -> None:
        """Replace state and covariance (e.g. the two-point velocity initialisation)."""
        ...

    def decay_velocity(self, factor: float, P_scale: FloatArray, P_add: FloatArray) -> None:
        """Velocity times ``factor``; covariance ``P * P_scale + P_add``."""
        ...


@lru_cache(maxsize=64)
def process_noise(dt: float, q: float, q_vertical: float) -> FloatArray:
    """Q of the constant-velocity model with white acceleration of variance q (z: q_vertical).
    Cached (most frames share one dt): read-only."""
    Q = np.zeros((6, 6))
    for axis in range(3):
        var = q_vertical if axis == 2 else q
        Q[axis, axis] = var * dt**4 / 4.0
        Q[axis, axis + 3] = Q[axis + 3, axis] = var * dt**3 / 2.0
        Q[axis + 3, axis + 3] = var * dt**2
    Q.setflags(write=False)
    return Q


@lru_cache(maxsize=64)
def transition(dt: float) -> FloatArray:
    """F of the constant-velocity model over ``dt``. Cached: read-only."""
    F = np.eye(6)
    F[:3, 3:] = np.eye(3) * dt
    F.setflags(write=False)
    return F


_H = np.hstack([np.eye(3), np.zeros((3, 3))])  # a centre is observed: the first three states
_I6 = np.eye(6)


class ConstantVelocityKF:
    """The default model: a constant-velocity Kalman filter observing position.

    ``measurement_noise_m``: σ of an observed centre; the initial velocity variance is
    ``INITIAL_VELOCITY_VAR`` (m/s)² until a second observation gives the velocity. The
    equations are filterpy's ``KalmanFilter`` (Joseph-form update), written out: the same
    numbers, without importing filterpy (which imports scipy.stats: a second of CPU per run).
    """

    INITIAL_VELOCITY_VAR = 1.0

    def __init__(self, center_map_m: FloatArray, measurement_noise_m: float) -> None:
        self._x: FloatArray = np.r_[center_map_m, np.zeros(3)].reshape(6, 1)
        r = measurement_noise_m**2
        self._R: FloatArray = np.eye(3) * r
        v = self.INITIAL_VELOCITY_VAR
        self._P: FloatArray = np.diag([r, r, r, v, v, v])

    @property
    def x(self) -> FloatArray:
        state: FloatArray = self._x[:, 0]
        return state

    @property
    def P(self) -> FloatArray:
        return self._P

    def predict(self, dt_s: float, q: float, q_vertical: float) -> None:
        F = transition(dt_s)
        self._x = np.dot(F, self._x)
        self._P = np.dot(np.dot(F, self._P), F.T) + process_noise(dt_s, q, q_vertical)

    def update(self, center_map_m: FloatArray) -> None:
        z = np.asarray(center_map_m, dtype=np.float64).reshape(3, 1)
        y = z - np.dot(_H, self._x)
        PHT = np.dot(self._P, _H.T)
        S = np.dot(_H, PHT) + self._R
        K = np.dot(PHT, np.linalg.inv(S))
        self._x = self._x + np.dot(K, y)
        I_KH = _I6 - np.dot(K, _H)
        self._P = np.dot(np.dot(I_KH, self._P), I_KH.T) + np.dot(np.dot(K, self._R), K.T)

    def reset(self, x: FloatArray, P: FloatArray) -> None:
        self._x = np.asarray(x, dtype=np.float64).reshape(6, 1)
        self._P = P

    def decay_velocity(self, factor: float, P_scale: FloatArray, P_add: FloatArray) -> None:
        self._x[3:, 0] *= factor
        self._P = self._P * P_scale + P_add


# name -> factory(center_map_m, measurement_noise_m)
MOTION_MODELS: dict[str, Callable[[FloatArray, float], MotionModel]] = {
    "constant_velocity": ConstantVelocityKF,
}


def make_motion_model(name: str, center_map_m: FloatArray, measurement_noise_m: float) -> MotionModel:
    """A new track's model of the registered kind ``name``."""
    try:
        factory = MOTION_MODELS[name]
    except KeyError:
        known = ", ".join(MOTION_MODELS)
        raise ConfigError(f"motion_model {name!r}: unknown; expected one of {known}") from None
    return factory(center_map_m, measurement_noise_m)
