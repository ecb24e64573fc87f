"""The sweep's driver: reads the sweep, skips the items finished in the output folder, runs the
others on a Dask cluster (a LocalCluster it starts, or an existing one by its scheduler address)
and writes each item as it comes back (records.py). docs/sweep.md.
"""
import logging
import os
import signal
import sys
import time

from . import records, spec
from .progress import Progress


def _cores():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def local_cluster(workers, threads=None):
    """N worker processes of one Dask thread each, the cores shared among them: `threads` (default
    cores // N) is lavapipe's LP_NUM_THREADS and the renders' threads= (unless the task gives it).
    The workers ignore Ctrl-C: the driver stops them."""
    from distributed import LocalCluster
    threads = threads or max(1, _cores() // workers)
    env = {"LP_NUM_THREADS": str(threads), "EIKON_SWEEP_THREADS": str(threads)}
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                            dashboard_address=":0", silence_logs=logging.ERROR, env=env)
    finally:
        signal.signal(signal.SIGINT, previous)


def _client(workers, scheduler):
    from distributed import Client
    if scheduler:
        try:
            if os.path.isfile(scheduler):  # dask-scheduler --scheduler-file FILE
                return Client(scheduler_file=scheduler, timeout=10, set_as_default=False), None
            return Client(scheduler, timeout=10, set_as_default=False), None
        except (OSError, TimeoutError) as e:
            raise spec.SweepError(f"cannot reach the Dask scheduler at '{scheduler}': {e}") from None
    cluster = local_cluster(workers or _cores())
    return Client(cluster, set_as_default=False), cluster


def _dashboard(client):
    """The dashboard's address where it serves one: Dask's needs bokeh (python3-bokeh)."""
    try:
        import bokeh  # noqa: F401
    except ImportError:
        return None
    services = client.scheduler_info().get("services", {})
    return client.dashboard_link if "dashboard" in services else None


def _check(sweep):
    import eikon
    try:
        eikon.Scene.parse(sweep.scene, sweep.origin)
    except Exception as e:  # the scene every item starts from is refused: nothing would render
        raise spec.SweepError(str(e).strip().splitlines()[0]) from None


def sweep(sweep, out, workers=None, scheduler=None, progress=None, retry_failed=False,
          client=None):
    """Run a sweep (a SWEEP.json path, or its content as a dict) into the folder `out`; returns
    results.csv as a pandas DataFrame. workers: the LocalCluster's worker processes (default: one
    per core); scheduler: an existing Dask scheduler's address instead. Items finished in `out`
    by an earlier run are not run again (nor refused ones, unless retry_failed). Ctrl-C stops,
    keeping every finished item, and raises KeyboardInterrupt."""
    if workers is not None and (not isinstance(workers, int) or workers < 1):
        raise spec.SweepError(f"workers must be a whole number >= 1, got {workers!r}")
    s = spec.Sweep(sweep) if not isinstance(sweep, dict) else spec.Sweep(spec=sweep)
    items = s.items()
    _check(s)
    if os.path.exists(out) and not os.path.isdir(out):
        raise spec.SweepError(f"{out}: the output folder is a file")
    done = {k: r for k, r in records.load(out).items() if not (retry_failed and r.get("error"))}
    todo = [i for i in items if i.key not in done]
    try:
        if todo:
            _run(s, todo, out, done, (workers, scheduler, client), progress, len(items))
    finally:  # Ctrl-C too: the table of what is done (no folder where no cluster was reached)
        frame = records.table(items, done)
        if os.path.isdir(out) or not todo:
            os.makedirs(out, exist_ok=True)
            records.write_table(out, frame)
    return frame


def _run(s, todo, out, done, where, progress, total):
    from distributed import as_completed
    exposure = s.task.options.get("exposure", 0.0)
    workers, scheduler, given = where
    client, cluster = (given, None) if given is not None else _client(workers, scheduler)
    bar = Progress(total, total - len(todo), progress)
    futures = {}
    try:
        os.makedirs(out, exist_ok=True)
        link = _dashboard(client)
        if link:
            bar.note(f"eikon: Dask dashboard at {link}")
        from .worker import run_item
        by_key, token, folder = {}, records.marker(out), os.path.abspath(out)
        for item in todo:
            payload = {"index": item.index, "key": item.key, "scene": item.scene,
                       "origin": item.origin, "out": folder, "token": token, "stem": item.stem,
                       "exposure": exposure}
            f = client.submit(run_item, s.task.spec(), payload, pure=False,
                              key=f"eikon-item-{item.index}-{item.key[:16]}")
            futures[f] = item
            by_key[f.key] = item
        last_table = time.monotonic()
        for f in as_completed(list(futures), loop=client.loop):
            item = futures[f]
            done[item.key] = records.write(out, item, _result(f), exposure)
            bar.item(done[item.key])
            if time.monotonic() - last_table > 2.0:
                records.write_table(out, records.table(s.items(), done))
                bar.workers(client, by_key)
                last_table = time.monotonic()
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
        bar.close()
        if given is None:
            client.close()
        if cluster is not None:
            cluster.close()


def _result(future):
    """The worker's record of an item; a future that failed without one (its worker died too
    often, or the cluster lost it) is a row with the error, not kept: a re-run runs it again."""
    try:
        return future.result()
    except Exception as e:  # KilledWorker and the like
        return {"error": f"{type(e).__name__}: {e}", "persist": False}


def _parser():
    import argparse

    class Parser(argparse.ArgumentParser):
        def error(self, message):  # one line, as every eikon command says it
            print(f"eikon: error: {message} (run with --help)", file=sys.stderr)
            sys.exit(2)

    p = Parser(
        prog="eikon sweep", description="Many renders of one kind on Dask: the items of SWEEP.json "
        "(its \"vary\" pointers' cartesian product) into DIR/results.csv and their images.")
    p.add_argument("sweep", metavar="SWEEP.json")
    p.add_argument("-o", "--output", metavar="DIR", required=True, help="output folder")
    p.add_argument("--workers", type=int, metavar="N",
                   help="worker processes of a LocalCluster (default: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="an existing Dask scheduler (tcp://host:8786, or the file of "
                   "dask-scheduler --scheduler-file) instead of a LocalCluster")
    p.add_argument("--retry-failed", action="store_true", help="run refused items again")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def main(argv=None):
    p = _parser()
    a = p.parse_args(argv)
    if a.workers is not None and a.scheduler:
        p.error("--workers starts a LocalCluster; --scheduler uses an existing one: give one")
    start = time.monotonic()
    try:
        frame = sweep(a.sweep, a.output, workers=a.workers, scheduler=a.scheduler,
                      progress=False if a.no_progress else None, retry_failed=a.retry_failed)
    except spec.SweepError as e:
        print(f"eikon: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        n = len(records.load(a.output)) if os.path.isdir(a.output) else 0
        print(f"eikon: sweep interrupted; {n} finished item{'' if n == 1 else 's'} kept in "
              f"{a.output} (run it again to finish)", file=sys.stderr)
        return 130
    failed = int(frame["error"].notna().sum())
    print(f"eikon: sweep: {len(frame)} items, {failed} failed, in {time.monotonic() - start:.1f} s:"
          f" {os.path.join(a.output, 'results.csv')}", file=sys.stderr)
    return 1 if failed else 0
