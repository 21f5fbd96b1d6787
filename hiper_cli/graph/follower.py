"""A background process that keeps the scene graph up to date while documents are written.

The writer (an import, the benchmark, any program writing many frames per second) commits one
document transaction per frame; bringing the graph up to date (``sync.sync_graph``) costs
about half as much CPU again, plus the graph store's own compaction threads. On a 2-core robot
computer a follower process does that work on the other core: it opens the documents
read-only (SQLite WAL readers see only committed transactions) and owns the on-disk graph
store, replaying the changes after the graph's high-water mark every ``interval_s`` and once
more when told to stop. The writer's memory then holds no graph store at all.

Consistency does not depend on the follower: it only ever runs the same idempotent replay as
``open_kb``. If the writer is killed, the follower is killed with it (Linux parent-death
signal; elsewhere it notices that its parent is gone), and the next ``open_kb`` repairs the
graph. The follower is a plain ``python -m hiper_cli.graph.follower`` child process: stdin
closed = stop, its last stdout line = its report.

    with GraphFollower(kb, interval_s=1.0) as follower:
        ... kb.write_frame(...) ...
    follower.report   # what the follower did: syncs, documents, CPU seconds, peak memory
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from types import TracebackType
from typing import IO, TYPE_CHECKING

from hiper_cli.errors import KnowledgeBaseError

if TYPE_CHECKING:
    from hiper_cli.graph.kb import KnowledgeBase

__all__ = ["FollowerReport", "GraphFollower"]

START_TIMEOUT_S = 60.0


@dataclass
class FollowerReport:
    syncs: int = 0
    documents: int = 0
    links: int = 0
    cpu_s: float = 0.0
    sync_s: float = 0.0
    peak_rss_mb: float = 0.0
    catch_up_s: float = 0.0  # from the stop request until the graph had caught up
    errors: list[str] = field(default_factory=list)


class GraphFollower:
    """Run the graph sync of ``kb`` in a child process between ``start()`` and ``stop()``.

    While it runs, the parent's knowledge base has no local graph handle (the store admits one
    process): ``kb.query`` and ``kb.check`` raise until ``stop()``. A SPARQL-endpoint graph stays
    usable in the parent.
    """

    def __init__(self, kb: KnowledgeBase, interval_s: float = 1.0) -> None:
        self.kb = kb
        self.interval_s = interval_s
        self.report = FollowerReport()
        self._process: subprocess.Popen[str] | None = None
        self._stderr: IO[str] | None = None

    def start(self) -> GraphFollower:
        from hiper_cli.graph.scenegraph import LocalGraph

        kb = self.kb
        if kb.read_only:
            raise KnowledgeBaseError(f"{kb.location}: opened read-only; nothing for a graph follower to do")
        kb.sync_graph()  # start from a caught-up graph: the follower's replays stay small
        if isinstance(kb.graph, LocalGraph):
            kb.detach_graph()
        args = [
            sys.executable, "-m", "hiper_cli.graph.follower", "--docs", str(kb.docs.path),
            "--graph", kb.graph.location, "--kb-id", kb.kb_id,
            "--graphs", ",".join(g.value for g in kb.graphs()), "--detail", kb.config.observation_detail,
            "--batch", str(kb.config.sync_batch), "--interval-s", repr(self.interval_s),
            "--parent-pid", str(os.getpid()),
        ]
        # the child imports this hiper even when it runs from a source tree
        paths = (str(Path(__file__).resolve().parents[2]), os.environ.get("PYTHONPATH"))
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p)}
        self._stderr = tempfile.TemporaryFile("w+")  # noqa: SIM115 (lives as long as the child)
        try:
            self._process = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                             stderr=self._stderr, text=True, env=env)
        except OSError as err:
            kb.attach_graph()
            raise KnowledgeBaseError(f"cannot start the graph follower ({err})") from err
        assert self._process.stdout is not None
        line = _readline(self._process.stdout, START_TIMEOUT_S)
        if line.strip() != "ready":  # it failed to open the stores: stop() raises its error
            self.stop()
            raise KnowledgeBaseError(f"{kb.location}: the graph follower did not start")
        return self

    def stop(self) -> FollowerReport:
        """Let the follower catch up with every committed document, wait for it, and give the
        graph back to the parent."""
        process = self._process
        if process is None:
            return self.report
        self._process = None
        t0 = time.perf_counter()
        assert process.stdin is not None and process.stdout is not None
        with contextlib.suppress(OSError):
            process.stdin.close()  # the stop request
        out = process.stdout.read()
        code = process.wait()
        self.report.catch_up_s = time.perf_counter() - t0
        lines = out.strip().splitlines()
        try:
            message = json.loads(lines[-1]) if lines else {}
        except ValueError:
            message = {}
        for key, value in message.items():
            if hasattr(self.report, key) and key != "catch_up_s":
                setattr(self.report, key, value)
        stderr = ""
        if self._stderr is not None:
            self._stderr.seek(0)
            stderr = self._stderr.read().strip()
            self._stderr.close()
        if self.kb.graph_detached:
            self.kb.attach_graph()
        if code != 0 or self.report.errors:
            detail = "; ".join(self.report.errors) or (stderr.splitlines()[-1] if stderr else "no message")
            raise KnowledgeBaseError(
                f"{self.kb.location}: the graph follower failed (exit code {code}): {detail}; the "
                "documents are intact, 'hiper kb check' rebuilds the graph"
            )
        self.kb.sync_graph()  # nothing left unless the follower died; then this repairs
        return self.report

    def __enter__(self) -> GraphFollower:
        return self.start()

    def __exit__(
        self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None
    ) -> None:
        if kind is None:
            self.stop()
        else:  # the writer failed: still leave a consistent graph, and its error in front
            with contextlib.suppress(KnowledgeBaseError):
                self.stop()


def _readline(stream: IO[str], timeout_s: float) -> str:
    """One line from a child's stdout, or "" after ``timeout_s``."""
    box: list[str] = []
    reader = threading.Thread(target=lambda: box.append(stream.readline()), daemon=True)
    reader.start()
    reader.join(timeout_s)
    return box[0] if box else ""


def _die_with_parent(parent_pid: int) -> None:
    """Ask Linux to kill this process when the parent dies (prctl PR_SET_PDEATHSIG)."""
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent_pid:  # it died before the request
        os._exit(1)


def follow(docs_path: str, location: str, kb_id: str, graph_iris: list[str], detail: str, batch: int,
           interval_s: float, stop: threading.Event, parent_pid: int) -> FollowerReport:
    """The follower's loop (in the child): sync every ``interval_s`` until ``stop``, then once
    more."""
    import pyoxigraph as ox

    from hiper_cli.graph.documents import DocumentStore
    from hiper_cli.graph.scenegraph import open_graph
    from hiper_cli.graph.sync import sync_graph

    report = FollowerReport()
    docs = DocumentStore(Path(docs_path), read_only=True)
    try:
        graph = open_graph(location)
    except BaseException:
        docs.close()
        raise
    graphs = [ox.NamedNode(g) for g in graph_iris]
    print("ready", flush=True)
    try:
        while True:
            stopping = stop.wait(interval_s)
            if os.getppid() != parent_pid:
                break
            done = sync_graph(docs, graph, kb_id, graphs, detail=detail, batch=batch)
            report.syncs += 1
            report.documents += done.documents
            report.links += done.links
            report.sync_s += done.seconds
            if stopping:
                break
    finally:
        graph.close()
        docs.close()
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m hiper_cli.graph.follower", description=__doc__)
    parser.add_argument("--docs", required=True)
    parser.add_argument("--graph", required=True)
    parser.add_argument("--kb-id", required=True)
    parser.add_argument("--graphs", required=True)
    parser.add_argument("--detail", default="summary")
    parser.add_argument("--batch", type=int, default=20000)
    parser.add_argument("--interval-s", type=float, default=1.0)
    parser.add_argument("--parent-pid", type=int, default=os.getppid())
    a = parser.parse_args(argv)
    _die_with_parent(a.parent_pid)
    stop = threading.Event()

    def wait_for_stop() -> None:
        sys.stdin.read()  # returns at EOF: the parent closed our stdin (or died)
        stop.set()

    threading.Thread(target=wait_for_stop, daemon=True).start()
    cpu0 = time.process_time()
    try:
        report = follow(a.docs, a.graph, a.kb_id, a.graphs.split(","), a.detail, a.batch, a.interval_s,
                        stop, a.parent_pid)
        code = 0
    except Exception as err:  # reported to the parent, which raises it as a KnowledgeBaseError
        report = FollowerReport(errors=[f"{type(err).__name__}: {err}"])
        code = 1
    report.cpu_s = time.process_time() - cpu0
    report.peak_rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(asdict(report)), flush=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
