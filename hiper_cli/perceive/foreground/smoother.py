"""Rauch-Tung-Striebel smoothing of a closed track's trajectory.

While a track lives, each row holds the filter's estimate from the observations so far; the
first rows rest on few of them. Once the track is closed, every row can use all of them: the
rows keep their stamps and take the smoothed positions and velocities (constant-velocity model,
the covariances and process noises the tracker stored per row).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hiper_cli.model import ROW_STAMP, ROW_STATE
from hiper_cli.perceive.foreground.motion import process_noise

if TYPE_CHECKING:
    from hiper_cli.perceive.foreground.track import Track

__all__ = ["smooth_trajectory"]


def smooth_trajectory(track: Track) -> None:
    """Rauch-Tung-Striebel smoothing of a closed track's trajectory rows (in place), for the
    constant-velocity model.

    The filter's estimates at the start of a track rest on few observations; once the track is
    closed every row can use all of them. Rows keep their stamps; positions and velocities
    become the smoothed ones. Only the rows from ``track.covariances_from`` on are smoothed:
    those before were smoothed when the track closed earlier (a walker lost, then resumed).
    """
    rows = track.trajectory[track.covariances_from:]
    n = len(rows)
    if n < 3:
        return
    xs = [np.asarray(r[ROW_STATE], dtype=np.float64) for r in rows]
    Ps = [np.asarray(P, dtype=np.float64) for P in track.covariances]
    for k in range(n - 2, -1, -1):
        dt = rows[k + 1][ROW_STAMP] - rows[k][ROW_STAMP]
        if dt <= 0:
            continue
        F = np.eye(6)
        F[:3, 3:] = np.eye(3) * dt
        x_k, P_k = np.asarray(rows[k][ROW_STATE], dtype=np.float64), track.covariances[k]
        x_pred = F @ x_k
        P_pred = F @ P_k @ F.T + process_noise(dt, *track.noises[k + 1])
        try:
            C = P_k @ F.T @ np.linalg.inv(P_pred)
        except np.linalg.LinAlgError:
            continue
        xs[k] = x_k + C @ (xs[k + 1] - x_pred)
        Ps[k] = P_k + C @ (Ps[k + 1] - P_pred) @ C.T
    for row, x in zip(rows, xs, strict=True):
        row[ROW_STATE] = x.tolist()
