"""Foreground recognition: the object map of a frame sequence (paper sections IV-E to IV-H).

``ForegroundStage`` (``stage.py``, registered as ``foreground``) runs each frame through five
steps; each has one file to start from, and ``ForegroundConfig`` (``config.py``) groups the
options by the same names:

1. **segment** (``segment.py``): the depth image becomes blobs, Euclidean clusters of the points
   the background layer does not explain (``background_filter.py``), with what stands on a
   table cut from it (``legs.py``, ``tables.py``); ``refine.py`` then trims, joins and splits the
   blobs with the detector's boxes (``carve.py``).
2. **associate** (``tracking.py``, ``Tracker._associate`` with ``association.py``): each blob,
   now a ``Measurement``, continues the track it is nearest to inside a gate, or starts one.
3. **fuse** (``track.py``): a ``Track`` is fused evidence, the boxes of the blobs it took
   (``seen_box.py``), their surface (``surface_samples.py``), its class votes; a track that is
   an object already tracked joins it (``stitch.py``, ``same_object.py``).
4. **track** (``motion.py``, ``moving.py``, ``smoother.py``): a Kalman filter per track; an object
   moves only with evidence (its blobs left where they were), so a static object keeps speed 0.
5. **classify** (``match.py`` names blobs with detections, Algorithm 4; ``class_vote.py`` gives a
   track its class from its votes): ``classes.py``, ``plausible.py`` and ``priors.py`` say
   which names a blob can take at all.

At the end of a session ``reidentify.py`` and ``vacated.py`` join this session's objects to
earlier sessions' instances. Values nobody should tune are named constants beside their code.
"""

from hiper_cli.perceive.foreground.config import ForegroundConfig
from hiper_cli.perceive.foreground.stage import ForegroundStage

__all__ = ["ForegroundConfig", "ForegroundStage"]
