"""One exception hierarchy for hiper.

Every message names the file, topic, frame or value that is wrong and says how to fix it.
The CLI prints ``HiperError`` as one red line and exits non-zero; any other exception is a
bug and keeps its traceback.
"""

from __future__ import annotations

__all__ = [
    "ConfigError",
    "DataError",
    "DownloadError",
    "GraphDamagedError",
    "HiperError",
    "KnowledgeBaseError",
    "LogError",
    "PerceptionError",
    "QueryError",
]


class HiperError(Exception):
    """Base class of every error hiper reports to a user."""

    exit_code: int = 1


class DataError(HiperError, ValueError):
    """A value handed to a hiper type has the wrong shape, dtype, unit or is not finite."""


class ConfigError(HiperError):
    """An option, a config file or a name in a registry is wrong."""

    exit_code = 2


class LogError(HiperError):
    """A sensor log (TUM folder, rosbag, MCAP, trajectory file) cannot be read."""


class KnowledgeBaseError(HiperError):
    """The knowledge base cannot be opened, written or is inconsistent."""


class GraphDamagedError(KnowledgeBaseError):
    """The scene graph cannot be opened or read; it is derived data, rebuilt by ``hiper kb check``."""


class PerceptionError(HiperError):
    """A recognition stage (background, foreground, detector, tracking) failed."""


class QueryError(HiperError):
    """A query cannot be parsed or answered."""


class DownloadError(HiperError):
    """A file (a detector model) cannot be downloaded, or is not the file that was expected."""
