"""Time writing, indexing and reading one synthetic 640×480 scene in the four log formats.

Run from the repository root: ``PYTHONPATH=. python scripts/bench_logs.py [frames]``.
Random images are incompressible, so PNG and file sizes are the worst case.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, "tests")

from logs_scene import make_frames

from hiper_cli.perceive.logs import BagWriter, TumWriter, open_log
from hiper_cli.types import CameraIntrinsics


def main() -> None:
    camera = CameraIntrinsics(640, 480, 525.0, 525.0, 319.5, 239.5, 5000.0)
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 60
    frames = make_frames(n=n, camera=camera)
    root = Path(tempfile.mkdtemp(prefix="hiper_bench_logs_"))
    paths = {"tum": root / "tum", "rosbag1": root / "log.bag", "rosbag2": root / "db3", "mcap": root / "mcap"}
    try:
        for kind, path in paths.items():
            start = time.perf_counter()
            with TumWriter(path, camera) if kind == "tum" else BagWriter(path, kind, camera) as writer:
                for frame in frames:
                    writer.write(frame)
            print(f"write {kind}: {(time.perf_counter() - start) / n * 1000:.1f} ms/frame")
        for kind, path in paths.items():
            start = time.perf_counter()
            reader = open_log(path)
            reader.info()
            indexed = time.perf_counter()
            count = sum(1 for _ in reader)
            done = time.perf_counter()
            print(f"read {kind}: open+index {1000 * (indexed - start):.0f} ms for {n} frames, "
                  f"iterate {1000 * (done - indexed) / count:.1f} ms/frame")
    finally:
        shutil.rmtree(root)


if __name__ == "__main__":
    main()
