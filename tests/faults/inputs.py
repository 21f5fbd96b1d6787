"""Bad inputs for the fault suite, generated in code: damaged files, hostile imports, huge images.

Every function writes into a folder it is given and returns the path it made; nothing here
imports hiper, so the same corpus can be run against an older checkout to measure it.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import struct
import zlib
from pathlib import Path
from typing import Any

FIXTURE = Path(__file__).resolve().parents[2] / "fixtures" / "house_small"
UUID = "0b6b7a4e-58d4-4c1e-9a4e-3f5d2a1c0001"
ENV_UUID = "0b6b7a4e-58d4-4c1e-9a4e-3f5d2a1c00e0"


def copy_log(dest: Path) -> Path:
    """A private copy of the fixture log that a case may damage."""
    shutil.copytree(FIXTURE, dest)
    return dest


def damage_middle(path: Path, size: int, seed: int = 7) -> None:
    """Overwrite ``size`` bytes in the middle of ``path`` with random bytes (same length)."""
    rng = random.Random(seed)
    length = path.stat().st_size
    start = max(0, length // 2 - size // 2)
    with path.open("r+b") as f:
        f.seek(start)
        f.write(bytes(rng.getrandbits(8) for _ in range(min(size, length - start))))


def binary_file(path: Path, size: int = 4096, seed: int = 3) -> Path:
    rng = random.Random(seed)
    path.write_bytes(bytes(rng.getrandbits(8) | 0x80 for _ in range(size)))
    return path


def huge_png(path: Path, width: int = 16000, height: int = 16000) -> Path:
    """A grey PNG of ``width`` x ``height`` pixels, all black: a few hundred KB on disk,
    ``width * height`` bytes once decoded."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I",
                                                                        zlib.crc32(kind + data) & 0xFFFFFFFF)

    compressor = zlib.compressobj(9)
    row = b"\x00" * (width + 1)
    body = b"".join(compressor.compress(row) for _ in range(height)) + compressor.flush()
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", body) + chunk(b"IEND",
                                                                                                  b""))
    return path


def _instance(**override: Any) -> dict[str, Any]:
    doc: dict[str, Any] = {
        "uuid": UUID, "layer": "foreground", "class": "cup",
        "box": {"center_m": [1.0, 2.0, 0.5], "extent_m": [0.1, 0.1, 0.2]},
        "frame": "map", "first_seen_s": 1.0, "last_seen_s": 2.0, "state": "static", "confidence": 0.0,
        "observation_count": 0, "speed_mps": 0.0, "data": None,
    }
    doc.update(override)
    return doc


def export_doc(instances: Any = None, environments: Any = None, **top: Any) -> dict[str, Any]:
    """A hiper JSON export holding ``instances`` (default: one valid cup of confidence 0.0)."""
    doc: dict[str, Any] = {
        "format": "hiper-kb-export", "version": 1, "kb_id": "faults", "exported_s": 0.0,
        "units": {"length": "m", "time": "s", "speed": "m/s"},
        "environments": [{"uuid": ENV_UUID, "name": "faults"}] if environments is None else environments,
        "sessions": [], "instances": [_instance()] if instances is None else instances,
        "analyses": [], "observations": [],
    }
    doc.update(top)
    return doc


def write_json(path: Path, data: Any) -> Path:
    path.write_text(json.dumps(data))
    return path


# name -> the document an import of it must refuse (or, for "valid", accept)
HOSTILE_IMPORTS: dict[str, Any] = {
    "uuid-with-angle-bracket": export_doc([_instance(uuid="abc>def")]),
    "uuid-with-space": export_doc([_instance(uuid="a b")]),
    "unknown-layer": export_doc([_instance(layer="basement")]),
    "class-not-text": export_doc([_instance(**{"class": 42})]),
    "box-of-text": export_doc([_instance(box="big")]),
    "box-extent-nan": export_doc([_instance(box={"center_m": [0, 0, 0], "extent_m": ["nan", 1, 1]})]),
    "box-two-numbers": export_doc([_instance(box={"center_m": [0, 0], "extent_m": [1, 1, 1]})]),
    "stamp-text": export_doc([_instance(first_seen_s="yesterday")]),
    "stamp-infinite": export_doc([_instance(last_seen_s=1e400)]),
    "missing-uuid": export_doc([{k: v for k, v in _instance().items() if k != "uuid"}]),
    "instances-not-a-list": export_doc("oops"),
    "instance-not-an-object": export_doc([17]),
    "top-level-array": [export_doc()],
    "wrong-format-name": export_doc(format="something-else"),
    "environment-without-name": export_doc(environments=[{"uuid": ENV_UUID}]),
}


def deep_nesting(path: Path, depth: int = 200_000) -> Path:
    path.write_text("[" * depth + "]" * depth)
    return path


def foreign_sqlite(folder: Path) -> Path:
    """Another program's ``documents.sqlite``: one table of its own, rollback journal."""
    import sqlite3

    folder.mkdir(parents=True, exist_ok=True)
    db = sqlite3.connect(folder / "documents.sqlite")
    db.execute("CREATE TABLE notes (id INTEGER PRIMARY KEY, text TEXT)")
    db.execute("INSERT INTO notes (text) VALUES ('keep me')")
    db.commit()
    db.close()
    return folder / "documents.sqlite"


def damage_graph(kb: Path, how: str) -> None:
    """Damage the scene graph of a knowledge base (RocksDB files under ``kb/graph``)."""
    graph = kb / "graph"
    if how == "sst":
        for sst in graph.glob("*.sst"):
            damage_middle(sst, max(64, sst.stat().st_size // 2))
    elif how == "current":
        (graph / "CURRENT").write_text("MANIFEST-999999\n")
    elif how == "manifest":
        for manifest in graph.glob("MANIFEST-*"):
            manifest.write_bytes(b"\x00garbage" * 16)
    elif how == "file":
        shutil.rmtree(graph)
        graph.write_text("not a graph")
    else:
        raise ValueError(how)


def damage_documents(kb: Path) -> None:
    path = kb / "documents.sqlite"
    damage_middle(path, path.stat().st_size // 4)


def tree_bytes(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def snapshot(path: Path) -> dict[str, tuple[int, int]]:
    """(size, mtime) of every file under ``path``: what a refused command must leave alone."""
    return {str(p.relative_to(path)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(path.rglob("*")) if p.is_file()}


def file_digest(path: Path) -> str:
    import hashlib

    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "absent"


def make_read_only(path: Path) -> None:
    for p in [path, *path.rglob("*")]:
        os.chmod(p, 0o555 if p.is_dir() else 0o444)
