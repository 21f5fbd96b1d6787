"""Writing output files so that a failure never destroys what was there before.

``atomic_output(path)`` yields a temporary path beside ``path``; only when the block finishes
is it renamed over ``path`` (one ``os.replace``, atomic on POSIX), so a full disk or a kill
half-way leaves the earlier file whole. A device or pipe (``/dev/null``, ``/dev/full``) is
written in place, since it cannot be replaced. ``refuse_inside`` keeps exports and conversions
out of a knowledge-base folder, which only its store writes.
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from hiper_cli.errors import DataError

__all__ = ["atomic_output", "folder_bytes", "os_error", "output_folder", "refuse_inside"]

KB_MARKER = "documents.sqlite"


def os_error(path: Path | str, err: OSError, what: str = "write") -> DataError:
    """A one-line error for an ``OSError`` on ``path``, with the fix."""
    reason = err.strerror or str(err)
    if err.errno in (errno.ENOSPC, errno.EFBIG, errno.EDQUOT):
        fix = "free some space or write elsewhere; any earlier file of that name is kept"
    elif err.errno in (errno.EROFS, errno.EACCES, errno.EPERM):
        fix = "choose a writable place"
    elif err.errno == errno.ENOENT:
        fix = "create the folder first or pass another path"
    elif err.errno == errno.EISDIR:
        fix = "pass a file name, not a folder"
    else:
        fix = "check the path and the disk"
    return DataError(f"{path}: cannot {what} it ({reason}); {fix}")


def folder_bytes(root: Path) -> int:
    """Bytes of the files under ``root`` (0 when it is absent). A file removed while it is
    counted (the graph store compacts its tables in the background) counts as gone."""
    total = 0
    for path in root.rglob("*") if root.exists() else ():
        with contextlib.suppress(FileNotFoundError):
            if path.is_file():
                total += path.stat().st_size
    return total


def refuse_inside(path: Path, what: str) -> None:
    """Raise when ``path`` lies in a knowledge-base folder (one holding ``documents.sqlite``)."""
    resolved = path.resolve()
    inside = [f for f in resolved.parents if (f / KB_MARKER).is_file()]
    if inside or resolved.name == KB_MARKER:
        where = inside[0] if inside else resolved.parent
        raise DataError(f"{path}: inside the knowledge base {where}; only hiper's store writes there; "
                        f"write the {what} elsewhere")


def output_folder(path: Path | str) -> Path:
    """Create the folder ``path`` (and its parents) for outputs; a one-line error when a file
    stands there or it cannot be made."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise DataError(f"{folder}: a file, not a folder; pass a folder for the outputs (-o DIR)")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise DataError(f"{folder}: a file stands in its path; pass another folder") from None
    except OSError as err:
        raise os_error(folder, err, "create") from err
    return folder


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_output(path: Path, *, suffix: str = "") -> Iterator[Path]:
    """A temporary path to write instead of ``path``, moved into place when the block ends
    without an error (deleted otherwise). ``OSError``s become ``DataError``s naming ``path``."""
    if path.is_dir():
        raise DataError(f"{path}: is a folder; pass a file name for the output")
    if path.exists() and not path.is_file():  # a device or a pipe: write it directly
        try:
            yield path
        except OSError as err:
            raise os_error(path, err) from err
        return
    parent = path.parent
    if not parent.is_dir():
        raise DataError(f"{parent}: no such folder; create it first or pass another output path")
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix + ".tmp", dir=parent)
        os.close(fd)
        os.chmod(tmp_name, 0o666 & ~_umask())
    except OSError as err:
        raise os_error(path, err) from err
    tmp = Path(tmp_name)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as err:
        raise os_error(path, err) from err
    finally:
        with contextlib.suppress(OSError):
            if tmp.exists():
                tmp.unlink()
