"""The output folder of a sweep: DIR/items/KEY.json, one record per finished item, written as
soon as the item is (after its images), atomically (a temporary beside it renamed over it); the
images beside results.csv (DIR/<stem>.exr and .png, written as one set); results.csv, one row per
item of the sweep, made from the records and rewritten atomically as items finish.
"""
import json
import os
import tempfile


def _atomic(path, write):
    folder = os.path.dirname(path) or "."
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=os.path.basename(path) + ".tmp-")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def load(out):
    """{key: record} of the items finished in `out` (unreadable records are not finished)."""
    done = {}
    folder = os.path.join(out, "items")
    if not os.path.isdir(folder):
        return done
    for name in os.listdir(folder):
        if not name.endswith(".json"):
            continue
        try:
            with open(os.path.join(folder, name), encoding="utf-8") as f:
                record = json.load(f)
        except (OSError, ValueError):
            continue
        files = [os.path.join(out, p) for p in record.get("files", {}).values()]
        if record.get("key") and all(os.path.isfile(p) for p in files):
            done[record["key"]] = record
    return done


MARKER = ".eikon-sweep"


def marker(out):
    """A token in DIR/.eikon-sweep: a worker that reads the same token there sees this output
    folder (the same machine, or a shared file system) and writes its images itself."""
    path = os.path.join(out, MARKER)
    try:
        with open(path, encoding="utf-8") as f:
            token = f.read().strip()
        if token:
            return token
    except OSError:
        pass
    token = os.urandom(16).hex()
    _atomic(path, lambda f: f.write(token + "\n"))
    return token


def sees(out, token):
    try:
        with open(os.path.join(out, MARKER), encoding="utf-8") as f:
            return f.read().strip() == token
    except OSError:
        return False


def write_images(out, stem, images, exposure=0.0):
    """Each image as an EXR and its PNG preview, one set, atomically; {column: file name}."""
    import eikon
    files = {}
    for name, rgb in images.items():
        base = stem if name == "image" else f"{stem}-{name}"
        prefix = "" if name == "image" else name + "_"
        eikon.write_image(os.path.join(out, base + ".exr"), rgb,
                          png=os.path.join(out, base + ".png"), exposure=exposure)
        files[prefix + "exr"], files[prefix + "png"] = base + ".exr", base + ".png"
    return files


def write(out, item, result, exposure=0.0):
    """Write one finished item: its images (unless its worker wrote them: result["files"]), then
    its record. Returns the record."""
    files = result.get("files") or write_images(out, item.stem, result.get("images", {}), exposure)
    record = {"key": item.key, "values": item.values, "figures": result.get("figures", {}),
              "files": files, "seconds": result.get("seconds"),
              "task_seconds": result.get("task_seconds"), "worker": result.get("worker"),
              "warm": result.get("warm"), "error": result.get("error")}
    if result.get("persist", True):
        os.makedirs(os.path.join(out, "items"), exist_ok=True)
        _atomic(os.path.join(out, "items", item.key + ".json"),
                lambda f: json.dump(record, f))
    return record


def _cell(value):
    return json.dumps(value) if isinstance(value, (list, dict)) else value


def table(items, records):
    """The DataFrame of results.csv: one row per item that has a record, in the items' order:
    index, a column per varied pointer, the figures, the files, seconds (the item on its worker),
    task_seconds (the task's own run in it), worker, warm, error."""
    import pandas as pd
    rows, figure_names, file_names = [], [], []
    for item in items:
        r = records.get(item.key)
        if r is None:
            continue
        for name in r["figures"]:
            if name not in figure_names:
                figure_names.append(name)
        for name in r["files"]:
            if name not in file_names:
                file_names.append(name)
        rows.append((item, r))
    columns = (["index"] + list(items[0].values if items else []) + figure_names + file_names +
               ["seconds", "task_seconds", "worker", "warm", "error"])
    data = []
    for item, r in rows:
        row = {"index": item.index, **{p: _cell(v) for p, v in item.values.items()}}
        row.update({n: r["figures"].get(n) for n in figure_names})
        row.update({n: r["files"].get(n) for n in file_names})
        row.update(seconds=r["seconds"], task_seconds=r.get("task_seconds"), worker=r["worker"], warm=r["warm"], error=r["error"])
        data.append(row)
    return pd.DataFrame(data, columns=columns)


def write_table(out, frame):
    _atomic(os.path.join(out, "results.csv"), lambda f: frame.to_csv(f, index=False))
