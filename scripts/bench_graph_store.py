"""The pyoxigraph measurements behind the scene graph's design (docs/kb.md), reproducible.

    PYTHONPATH=. python scripts/bench_graph_store.py [OBSERVATIONS]   (default 200000)

1. Insert rate of observation nodes (type + provenance link, or 4 quads with class and stamp)
   in batches of 20,000 observations, for ``Store.extend``, ``Store.bulk_extend``,
   ``Store.load`` and ``Store.bulk_load`` of N-Quads text.
2. Resident memory of the store process as the quads grow, with and without reads (400
   ``quads_for_pattern`` lookups per batch, as node refreshes do).
3. Whether a Python thread overlaps ``bulk_load`` (it does not: pyoxigraph holds the GIL).

Each case runs in a fresh subprocess on a fresh store in a temporary directory.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import textwrap

CASE = textwrap.dedent('''
    import json, random, resource, sys, tempfile, threading, time, uuid
    import pyoxigraph as ox
    mode, n, quads_per_obs, reads = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
    H = "https://w3id.org/hiper#"
    RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
    PROV = "http://www.w3.org/ns/prov#"
    XSD = "http://www.w3.org/2001/XMLSchema#"
    G = "<urn:hiper:kb:x:foreground>"
    store = ox.Store(tempfile.mkdtemp(dir=sys.argv[5]))
    instances = [str(uuid.uuid4()) for _ in range(5000)]
    subjects = []

    def rss_mb():
        with open("/proc/self/status") as f:
            return int(next(l for l in f if l.startswith("VmRSS")).split()[1]) / 1024

    def text(start, stop):
        lines = []
        for k in range(start, stop):
            u = str(uuid.uuid4()); subjects.append(u); s = f"<urn:uuid:{u}>"
            i = f"<urn:uuid:{instances[k // 100 % 5000]}>"
            lines.append(f"{s} <{RDF}type> <{H}Observation> {G} .\\n{i} <{PROV}wasDerivedFrom> {s} {G} .\\n")
            if quads_per_obs == 4:
                lines.append(f'{s} <{H}className> "chair" {G} .\\n'
                             f'{s} <{H}stampS> "{k * 0.1!r}"^^<{XSD}double> {G} .\\n')
        return "".join(lines).encode()

    def insert(data):
        if mode in ("extend", "bulk_extend"):
            getattr(store, mode)(list(ox.parse(data, format=ox.RdfFormat.N_QUADS)))
        else:
            getattr(store, mode)(data, format=ox.RdfFormat.N_QUADS)

    batch = 20000
    if mode.startswith("thread:"):  # bulk_load beside a spinning Python thread
        mode = mode.split(":", 1)[1]
        datas = [text(k, min(n, k + batch)) for k in range(0, n, batch)]
        t0 = time.perf_counter()
        for d in datas: insert(d)
        alone = time.perf_counter() - t0
        store2 = ox.Store(tempfile.mkdtemp(dir=sys.argv[5])); store = store2
        done = threading.Event(); spins = [0]
        def spin():
            while not done.is_set():
                sum(range(10000)); spins[0] += 1
        th = threading.Thread(target=spin); th.start()
        t0 = time.perf_counter()
        for d in datas: insert(d)
        beside = time.perf_counter() - t0
        done.set(); th.join()
        print(json.dumps({"case": "bulk_load beside a Python thread", "load_alone_s": round(alone, 2),
                          "load_beside_thread_s": round(beside, 2)}))
        sys.exit()
    t0, c0, build = time.perf_counter(), time.process_time(), 0.0
    curve = []
    for k in range(0, n, batch):
        b0 = time.perf_counter(); data = text(k, min(n, k + batch)); build += time.perf_counter() - b0
        insert(data)
        for _ in range(reads):
            list(store.quads_for_pattern(ox.NamedNode("urn:uuid:" + random.choice(subjects)), None, None))
        store.flush()
        curve.append(round(rss_mb()))
    wall = time.perf_counter() - t0 - build
    print(json.dumps({"case": mode, "observations": n, "quads_per_observation": quads_per_obs,
                      "reads_per_batch": reads, "obs_per_s": round(n / wall),
                      "rss_mb_first_last": [curve[0], curve[-1]],
                      "peak_rss_mb": round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)}))
''')


def run(args: list[str], tmp: str) -> dict[str, object]:
    out = subprocess.run([sys.executable, "-c", CASE, *args, tmp], capture_output=True, text=True, check=True)
    return dict(json.loads(out.stdout.strip().splitlines()[-1]))


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 200_000
    with tempfile.TemporaryDirectory(prefix="hiper-graph-bench-") as tmp:
        for mode in ("extend", "bulk_extend", "load", "bulk_load"):
            print(run([mode, str(n), "4", "0"], tmp), flush=True)
        print(run(["bulk_load", str(n), "2", "0"], tmp), flush=True)
        print(run(["bulk_load", str(n), "2", "400"], tmp), flush=True)
        print(run(["thread:bulk_load", str(n), "2", "0"], tmp), flush=True)


if __name__ == "__main__":
    main()
