"""The sweep's progress on a terminal: a tqdm bar of items done (failed counted apart) with its
ETA and each worker's state (busy or idle, items done); nothing where stderr is not a terminal
unless asked (progress=True), and nothing with progress=False."""
import sys


class Progress:
    def __init__(self, total, done, enabled):
        self.failed, self.per_worker, self.busy = 0, {}, {}
        self.bar = None
        if enabled is False or (enabled is None and not sys.stderr.isatty()):
            return
        try:
            from tqdm import tqdm
        except ImportError:
            return
        self.bar = tqdm(total=total, initial=done, unit="item", file=sys.stderr,
                        dynamic_ncols=True, desc="sweep")

    def note(self, line):
        (self.bar.write if self.bar else print)(line, file=sys.stderr)

    def item(self, record):
        worker = record.get("worker") or "?"
        self.per_worker[worker] = self.per_worker.get(worker, 0) + 1
        if record.get("error"):
            self.failed += 1
        if self.bar:
            self.bar.update(1)
            self._postfix()

    def workers(self, client, by_key):
        """Each worker's state from the scheduler: the items it holds now."""
        if not self.bar:
            return
        try:
            processing = client.processing()
            names = {a: str(w.get("name", a)) for a, w in
                     client.scheduler_info().get("workers", {}).items()}
        except Exception:  # a scheduler going away mid-sweep: keep the last state
            return
        self.busy = {names.get(a, a): len([k for k in keys if k in by_key])
                     for a, keys in processing.items()}
        self._postfix()

    def _postfix(self):
        state = " ".join(f"{w}:{'busy' if self.busy.get(w) else 'idle'}/{self.per_worker.get(w, 0)}"
                         for w in sorted(set(self.busy) | set(self.per_worker)))
        self.bar.set_postfix_str(f"failed {self.failed} | workers {state}", refresh=True)

    def close(self):
        if self.bar:
            self.bar.close()
