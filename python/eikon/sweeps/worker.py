"""What a Dask worker runs for one item (run_item), with its warm sessions.

A worker process keeps the sessions it prepared (a Renderer: the voxelised volume, its pipelines
and simulated light) keyed by the part of the scene a session depends on (Task.session_part: all
but the camera), the EIKON_SWEEP_SESSIONS (default 2) used last. An item whose scene differs from
a kept one only in its camera renders on it: a turntable voxelises and simulates once per worker.
Nothing of the worker reaches the result: an item's figures are those of the same item run alone.
"""
import collections
import hashlib
import json
import os
import time

from . import records, tasks

_sessions = collections.OrderedDict()  # session key -> (eikon.Scene, session)


def _kept():
    try:
        return max(1, int(os.environ.get("EIKON_SWEEP_SESSIONS", "2")))
    except ValueError:
        return 2


def _worker_name():
    try:
        from distributed import get_worker
        w = get_worker()
        if w.name is None:
            return w.address
        return f"w{w.name}" if isinstance(w.name, int) else str(w.name)  # a LocalCluster's 0, 1
    except (ImportError, ValueError):
        return f"pid{os.getpid()}"


def _trace(what, key):
    """EIKON_SWEEP_TRACE=FILE: one line per item started and finished ("start KEY PID"), for
    following a sweep's items across workers (the tests kill a worker in the middle of one)."""
    path = os.environ.get("EIKON_SWEEP_TRACE")
    if path:
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{what} {key} {os.getpid()}\n")


def _session(task, scene_dict, origin):
    import eikon
    scene = eikon.Scene.parse(scene_dict, origin)  # refuses a bad item before any work
    part = json.dumps([task.kind, origin, task.session_part(scene_dict)], sort_keys=True)
    key = hashlib.sha256(part.encode()).hexdigest()
    if key in _sessions:
        _sessions.move_to_end(key)
        kept_scene, session = _sessions[key]
        kept_scene.camera = scene.camera
        return kept_scene, session, True
    session = task.prepare(scene)
    _sessions[key] = (scene, session)
    while len(_sessions) > _kept():
        _sessions.popitem(last=False)
    return scene, session, False


def run_item(task_spec, item):
    """Run one item ({"index", "key", "scene", "origin"}, and "out", "token", "stem", "exposure"
    where the driver's folder may be visible) of the task `task_spec`; returns its record:
    figures, task_seconds (the task's own run: the render), images (or files: the worker saw the driver's folder, records.sees, and wrote them
    there, sparing the driver and the network), seconds, worker, warm (a kept session served it)
    and error (the refusal's text, the others None)."""
    start = time.perf_counter()
    _trace("start", item["key"])
    record = {"index": item["index"], "key": item["key"], "worker": _worker_name(),
              "figures": {}, "images": {}, "warm": False, "error": None}
    try:
        task = tasks.make(task_spec["kind"], {k: v for k, v in task_spec.items() if k != "kind"})
        scene, session, record["warm"] = _session(task, item["scene"], item["origin"])
        run_start = time.perf_counter()
        record["figures"], record["images"] = task.run(session, scene)
        record["task_seconds"] = time.perf_counter() - run_start
        out = item.get("out")
        if out and records.sees(out, item.get("token")):  # the driver's folder: write here
            record["files"] = records.write_images(out, item["stem"], record.pop("images"),
                                                   item.get("exposure", 0.0))
    except Exception as e:  # a refused item is a row with its error; the others go on
        record["error"] = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
    record["seconds"] = time.perf_counter() - start
    _trace("end", item["key"])
    return record
