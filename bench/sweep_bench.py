#!/usr/bin/python3
"""The sweep's scaling and per-item overhead (docs/performance.md "Sweeps").

  PYTHONPATH=build/python /usr/bin/python3 bench/sweep_bench.py [--items 24] [--width 160]
      [--height 120] [--spp 4] [--resolution 64]

A camera-only turntable of glass_sphere (--items positions). The item's own render is timed in
this process on a warm Renderer with one lavapipe thread (the median of --items renders). Then for
1 worker x 1 thread, 2 workers x 1 thread and 1 worker x all cores, a LocalCluster is started,
every worker warmed (its session prepared), and the sweep timed from submission to its last row
(files and records written): items/s, and the per-item overhead = seconds per item of the 1 x 1
sweep less the render alone. Prints one table; the scheduler's own overhead per task is the 1 x 1
overhead less the files and records written (timed apart).
"""
import argparse
import json
import math
import os
import statistics
import sys
import tempfile
import time

os.environ["LP_NUM_THREADS"] = "1"  # this process's renders: one core, as a 1-thread worker
import eikon  # noqa: E402
from eikon.sweeps import records, run, spec, worker  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def sweep_spec(a):
    positions = [[round(60 * math.sin(t), 6), 0, round(-60 * math.cos(t), 6)]
                 for t in (2 * math.pi * k / a.items for k in range(a.items))]
    with open(os.path.join(HERE, "..", "scenes", "glass_sphere.json")) as f:
        scene = json.load(f)
    scene["volume"]["resolution"] = a.resolution
    return {"scene": scene, "task": {"kind": "render", "width": a.width, "height": a.height,
                                     "spp": a.spp},
            "vary": {"/camera/position": positions}}


def render_alone(a):
    s = spec.Sweep(spec=sweep_spec(a))
    items = s.items()
    r = eikon.Renderer(eikon.Scene.parse(items[0].scene, items[0].origin))
    kw = {k: v for k, v in s.task.spec().items() if k != "kind"}
    r.render(progress=False, threads=1, **kw)
    times, write_times = [], []
    with tempfile.TemporaryDirectory() as out:
        for item in items:
            r.scene.camera = eikon.Scene.parse(item.scene, item.origin).camera
            t = time.perf_counter()
            rgb = r.render(progress=False, threads=1, **kw)
            times.append(time.perf_counter() - t)
            t = time.perf_counter()
            records.write(out, item, {"images": {"image": rgb}, "figures": {}})
            write_times.append(time.perf_counter() - t)
    return statistics.median(times), statistics.median(write_times)


def timed_sweep(a, workers, threads):
    from distributed import Client
    cluster = run.local_cluster(workers, threads)
    client = Client(cluster, set_as_default=False)
    try:
        client.wait_for_workers(workers)
        s = spec.Sweep(spec=sweep_spec(a))
        first = s.items()[0]
        client.run(worker.run_item, s.task.spec(), {"index": 0, "key": "warm", "scene": first.scene,
                                                     "origin": first.origin})
        with tempfile.TemporaryDirectory() as out:
            t = time.perf_counter()
            frame = eikon.sweep(sweep_spec(a), out, client=client, progress=False)
            wall = time.perf_counter() - t
        assert frame["error"].isna().all() and frame["warm"].all(), frame
        return wall
    finally:
        client.close()
        cluster.close()


def main():
    p = argparse.ArgumentParser()
    for name, default in (("items", 24), ("width", 160), ("height", 120), ("spp", 4),
                          ("resolution", 64)):
        p.add_argument("--" + name, type=int, default=default)
    a = p.parse_args()
    alone, write = render_alone(a)
    print(f"render alone (1 thread): {alone:.3f} s; its EXR, PNG and record written: {write:.3f} s")
    rows = []
    for workers, threads in ((1, 1), (2, 1), (1, run._cores())):
        wall = timed_sweep(a, workers, threads)
        rows.append((workers, threads, wall))
        print(f"{workers} worker(s) x {threads} thread(s): {a.items} items in {wall:.2f} s = "
              f"{a.items / wall:.2f} items/s", flush=True)
    base = a.items / rows[0][2]
    print(f"scaling 2 workers / 1 worker (1 thread each): {a.items / rows[1][2] / base:.2f}x; "
          f"2 x 1 thread / 1 x {rows[2][1]} threads: {rows[2][2] / rows[1][2]:.2f}x")
    overhead = rows[0][2] / a.items - alone
    print(f"per-item overhead, warm 1-thread worker: {overhead:.3f} s above the render "
          f"({overhead - write:.3f} s without writing the files)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
