"""Why the knowledge base does not use TinyDB: its JSON storage rewrites the whole file per write.

Not a dependency of hiper; run it in any environment with TinyDB installed:

    pip install tinydb && python scripts/bench_tinydb.py [TOTAL_DOCUMENTS]

Inserts 20 observation-like documents per frame (one ``insert_multiple`` per frame, like one
perceive frame) and prints documents per CPU-second for each block of 1,000.
"""

from __future__ import annotations

import sys
import tempfile
import time
import uuid
from pathlib import Path

from tinydb import TinyDB


def main(total: int = 6000, per_frame: int = 20) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        db = TinyDB(Path(tmp) / "kb.json")
        block_start = time.process_time()
        for done in range(0, total, per_frame):
            db.insert_multiple(
                {"uuid": str(uuid.uuid4()), "type": "observation", "class": "person",
                 "stamp_s": done / 200.0, "box": {"center_m": [1.0, 2.0, 0.9], "extent_m": [0.5, 0.4, 1.7]}}
                for _ in range(per_frame)
            )
            if (done + per_frame) % 1000 == 0:
                cpu = time.process_time() - block_start
                print(f"{done + per_frame:>6} documents: {1000 / cpu:8.0f} documents per CPU-second")
                block_start = time.process_time()
        db.close()


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 6000)
