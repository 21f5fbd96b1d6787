"""What a ``--kb`` value names: a knowledge-base folder, or the URL of a SPARQL 1.1 endpoint.

Only ``http://`` and ``https://`` (any letter case) name endpoints; any other ``scheme://``
(``ftp://``, ``s3://``, ``file://``) is refused rather than taken as a folder name.
"""

from __future__ import annotations

import re
import urllib.parse
from pathlib import Path

from hiper_cli.errors import KnowledgeBaseError

__all__ = ["kb_location"]

_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.-]*):(//|\\\\)")


def kb_location(location: str | Path) -> tuple[bool, str]:
    """``(remote, text)``: whether ``location`` is an endpoint URL (then normalised to a lower-case
    scheme) or a folder path. Raises ``KnowledgeBaseError`` for other schemes and hostless URLs."""
    text = str(location)
    if not text.strip():
        raise KnowledgeBaseError("--kb '': empty; pass a knowledge-base folder, e.g. --kb scene.hiper")
    found = _SCHEME.match(text)
    if found is None:
        return False, text
    scheme = found.group(1).lower()
    if scheme not in ("http", "https"):
        raise KnowledgeBaseError(
            f"--kb {text}: '{scheme}://' is not supported; pass a knowledge-base folder or the "
            "http(s):// URL of a SPARQL endpoint"
        )
    url = scheme + text[len(found.group(1)):]
    if not urllib.parse.urlsplit(url).netloc:
        raise KnowledgeBaseError(f"--kb {text}: no host in the URL; e.g. --kb http://localhost:7878")
    return True, url
