#!/usr/bin/python3
"""The sweep's scaling and per-item overhead (docs/performance.md "Sweeps").

  PYTHONPATH=build/python /usr/bin/python3 bench/sweep_bench.py [--items 24] [--width 400]
      [--height 300] [--spp 16] [--resolution 64] [--rounds 3]

A camera-only turntable of glass_sphere (--items positions). The item's own render is timed in
this process on a warm Renderer with one lavapipe thread (the median of --items renders), and
the files a worker writes for it. Then for 1 worker x 1 thread, 2 workers x 1 thread and
1 worker x all cores, a LocalCluster is started, every worker warmed (its session prepared) and
the sweep timed from submission to its last row, --rounds times alternating (the fastest of each
kept: the run least disturbed by other processes): items/s, the CPU seconds per item (workers
and driver), and the per-item overhead = seconds per item of the 1 x 1 sweep less the mean
render in it (task_seconds, timed in the worker). Last, the scheduler's rate of no-op tasks and
the driver's time per record: the bounds of scaling out.
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


def _noop(x):
    return x


def _cpu():
    return time.process_time()


def scheduler_rate(workers):
    """No-op tasks per second through a LocalCluster's scheduler (its own per-task cost), and the
    driver's cost of one item's record (written with fsync, files already there)."""
    from distributed import Client
    cluster = run.local_cluster(workers, 1)
    client = Client(cluster, set_as_default=False)
    try:
        client.wait_for_workers(workers)
        client.gather(client.map(_noop, range(50), pure=False))
        t = time.perf_counter()
        client.gather(client.map(_noop, range(1000), pure=False))
        rate = 1000 / (time.perf_counter() - t)
    finally:
        client.close()
        cluster.close()
    s = spec.Sweep(spec=sweep_spec(argparse.Namespace(items=200, resolution=32, width=8,
                                                       height=8, spp=1)))
    with tempfile.TemporaryDirectory() as out:
        t = time.perf_counter()
        for item in s.items():
            records.write(out, item, {"files": {"exr": "x.exr"}, "figures": {"mean_r": 0.5}})
        record = (time.perf_counter() - t) / 200
    return rate, record


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
            cpu0, own0 = sum(client.run(_cpu).values()), time.process_time()
            t = time.perf_counter()
            frame = eikon.sweep(sweep_spec(a), out, client=client, progress=False)
            wall = time.perf_counter() - t
            cpu = sum(client.run(_cpu).values()) - cpu0 + time.process_time() - own0
        assert frame["error"].isna().all() and frame["warm"].all(), frame
        return wall, float(frame["task_seconds"].mean()), cpu / a.items
    finally:
        client.close()
        cluster.close()


def main():
    p = argparse.ArgumentParser()
    for name, default in (("items", 24), ("width", 400), ("height", 300), ("spp", 16),
                          ("resolution", 64), ("rounds", 3)):
        p.add_argument("--" + name, type=int, default=default)
    a = p.parse_args()
    alone, write = render_alone(a)
    print(f"load average {os.getloadavg()[0]:.1f} on {run._cores()} cores")
    print(f"render alone (1 thread): {alone:.3f} s; its EXR, PNG and record written: {write:.3f} s")
    configs = ((1, 1), (2, 1), (1, run._cores()))
    best = {}
    for _ in range(a.rounds):  # alternating, the fastest of each: the least disturbed by others
        for workers, threads in configs:
            wall, task, cpu = timed_sweep(a, workers, threads)
            print(f"  {workers} worker(s) x {threads} thread(s): {wall:.2f} s, "
                  f"{cpu:.3f} CPU s per item (workers and driver)", flush=True)
            if (workers, threads) not in best or wall < best[(workers, threads)][0]:
                best[(workers, threads)] = (wall, task, cpu)
    rows = [(w, t, *best[(w, t)]) for w, t in configs]
    for workers, threads, wall, _, cpu in rows:
        print(f"{workers} worker(s) x {threads} thread(s): {a.items} items in {wall:.2f} s = "
              f"{a.items / wall:.2f} items/s (fastest of {a.rounds}); {cpu:.3f} CPU s per item; "
              f"{cpu * a.items / wall:.2f} cores received")
    base = a.items / rows[0][2]
    print(f"scaling 2 workers / 1 worker (1 thread each): {a.items / rows[1][2] / base:.2f}x; "
          f"2 x 1 thread / 1 x {rows[2][1]} threads: {rows[2][2] / rows[1][2]:.2f}x")
    rate, record = scheduler_rate(2)
    print(f"scheduler: {rate:.0f} no-op tasks/s (2 workers); the driver's record per item: "
          f"{record * 1e3:.1f} ms")
    overhead = rows[0][2] / a.items - rows[0][3]
    print(f"per-item overhead, warm 1-thread worker: {overhead:.3f} s above its render "
          f"({rows[0][3]:.3f} s, timed in the worker; {overhead - write:.3f} s without writing the "
          "files)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
