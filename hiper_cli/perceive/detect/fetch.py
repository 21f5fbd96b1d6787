"""Getting a detector model onto this machine: download (resumable, verified) or add a file.

``fetch_model`` downloads a catalog entry from its official URL (or a mirror, ``url=``) into
``DIR/NAME/NAME.onnx.part``, resuming a part left by an interrupted run with an HTTP Range
request, checks the sha256 and only then renames the part to ``NAME.onnx``: the model's name
never holds a partial or unverified file. A checksum mismatch deletes the part. An entry with
no known sha256 is fetched only with ``allow_unverified`` (its sha256 is then reported so
that it can be pinned). ``add_model`` copies a file the user has, checked the same way.
"""

from __future__ import annotations

import hashlib
import http.client
import os
import shutil
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hiper_cli.errors import ConfigError, DownloadError
from hiper_cli.perceive.detect.catalog import ModelEntry, model_path

__all__ = ["FetchResult", "add_model", "fetch_model", "sha256_of"]

Progress = Callable[[int, int | None], None]
_CHUNK = 1 << 16


@dataclass(frozen=True)
class FetchResult:
    """Where the model is, its sha256, whether it matched a known sha256 (False: none known),
    the bytes transferred this time and where a download resumed from (0: from the start)."""

    path: Path
    sha256: str
    verified: bool
    downloaded_bytes: int
    resumed_from: int


def sha256_of(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _check_url(entry: ModelEntry, url: str | None, allow_unverified: bool) -> str:
    source = url or entry.url
    if source is None:
        raise ConfigError(f"{entry.name}: its authors publish no ONNX file; export one ({entry.export}) "
                          f"and run 'hiper models add {entry.name}.onnx', or pass --from URL")
    if entry.sha256 is None and not allow_unverified:
        raise ConfigError(f"{entry.name}: no verified sha256 is known for {source}; pass --trust-unverified "
                          "to download it anyway (its sha256 is then printed so you can check it)")
    if not source.startswith(("https://", "http://")):
        raise ConfigError(f"{source}: not an http(s) URL; pass --from https://HOST/PATH/{entry.file_name}")
    return source


def _open(source: str, offset: int, timeout_s: float) -> tuple[Any, int]:
    """The response to a GET (from ``offset`` when > 0) and the offset it actually starts at."""
    headers = {"User-Agent": "hiper-models"}
    if offset > 0:
        headers["Range"] = f"bytes={offset}-"
    try:
        response = urllib.request.urlopen(urllib.request.Request(source, headers=headers), timeout=timeout_s)
    except urllib.error.HTTPError as err:
        if err.code == 416 and offset > 0:  # the part is already whole
            return None, offset
        raise DownloadError(f"{source}: the server answered HTTP {err.code} {err.reason}; check the URL "
                            "or download the file by hand and run 'hiper models add FILE'") from err
    except (urllib.error.URLError, OSError, http.client.HTTPException) as err:
        reason = getattr(err, "reason", err)
        raise DownloadError(f"cannot download {source} ({reason}); on a machine with network, download "
                            "that URL and run 'hiper models add FILE' here") from err
    status = getattr(response, "status", 200)
    return response, offset if status == 206 else 0


def _stream(response: Any, part: Path, start: int, progress: Progress | None, source: str) -> int:
    """Append (from ``start``) the response body to ``part``; bytes written."""
    length = response.headers.get("Content-Length")
    total = start + int(length) if length is not None else None
    written = 0
    try:
        with part.open("r+b" if start > 0 else "wb") as out:
            out.seek(start)
            out.truncate()
            while chunk := response.read(_CHUNK):
                out.write(chunk)
                written += len(chunk)
                if progress is not None:
                    progress(start + written, total)
    except (OSError, http.client.HTTPException) as err:
        raise DownloadError(f"download of {source} stopped after {start + written} bytes ({err}); run the "
                            f"same command again to resume from {part}") from err
    finally:
        response.close()
    if total is not None and start + written < total:
        raise DownloadError(f"download of {source} stopped after {start + written} of {total} bytes (the "
                            f"connection closed); run the same command again to resume from {part}")
    return written


def _verify(entry: ModelEntry, candidate: Path, source: str) -> tuple[str, bool]:
    digest = sha256_of(candidate)
    if entry.sha256 is not None and digest != entry.sha256:
        candidate.unlink(missing_ok=True)
        raise DownloadError(f"{source}: sha256 {digest} is not the known {entry.name} ({entry.sha256}); "
                            "the file was deleted; check the URL or mirror")
    return digest, entry.sha256 is not None


def fetch_model(
    entry: ModelEntry, directory: Path, *, url: str | None = None, allow_unverified: bool = False,
    progress: Progress | None = None, timeout_s: float = 30.0,
) -> FetchResult:
    """Download ``entry`` into ``directory`` (see the module doc); an existing verified file is kept."""
    source = _check_url(entry, url, allow_unverified)
    target = model_path(directory, entry.name)
    if target.is_file() and entry.sha256 is not None and sha256_of(target) == entry.sha256:
        return FetchResult(target, entry.sha256, True, 0, 0)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise DownloadError(f"{target.parent}: cannot create it ({err}); pass --dir to a writable "
                            "folder") from err
    part = target.with_name(target.name + ".part")
    offset = part.stat().st_size if part.is_file() else 0
    response, start = _open(source, offset, timeout_s)
    written = 0 if response is None else _stream(response, part, start, progress, source)
    digest, verified = _verify(entry, part, source)
    os.replace(part, target)
    return FetchResult(target, digest, verified, written, start)


def add_model(entry: ModelEntry, source: Path, directory: Path) -> FetchResult:
    """Copy a model file the user has into ``directory`` as ``entry``; a known sha256 must match."""
    if not source.is_file():
        raise ConfigError(f"{source}: no such file; pass the path of an .onnx model")
    digest = sha256_of(source)
    if entry.sha256 is not None and digest != entry.sha256:
        raise DownloadError(f"{source}: sha256 {digest} is not the known {entry.name} ({entry.sha256}); "
                            f"add it under another name (--name my_{entry.name}) or use "
                            f"--detector onnx:{source}")
    target = model_path(directory, entry.name)
    part = target.with_name(target.name + ".part")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, part)
        os.replace(part, target)
    except OSError as err:
        part.unlink(missing_ok=True)
        raise DownloadError(f"{target}: cannot write it ({err}); pass --dir to a writable folder") from err
    return FetchResult(target, digest, entry.sha256 is not None, 0, 0)
