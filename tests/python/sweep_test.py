"""eikon.sweep and `eikon sweep` on a real Dask cluster (docs/sweep.md).

Run by CTest (python.sweep) with EIKON_PYTHON_DIR (the built module) and EIKON_BINARY. A
LocalCluster of 2 worker processes runs a few items: each row's figures equal those of the same
item rendered alone in this process (1e-9 relative: an item's result depends on the item only) and
its EXR holds that image; a refused item (an unknown material) is one row with its error while
the others complete; a re-run does no work (no item starts, nothing is rewritten); a worker killed
with SIGKILL in the middle of an item still leaves every row, each once, the item run again on
another worker; a gem sweep's rows (two pavilion angles) equal eikon.gem run alone on each item
(1e-9 relative), its pictures written beside the table; a separately started dask-scheduler with a
dask-worker on localhost runs the sweep through --scheduler; a bad sweep file is one line naming
the file and the JSON path, with no output.
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

import eikon  # noqa: E402

EIKON = os.environ.get("EIKON_BINARY")
SCENE = {
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 32, "height": 24},
    "environment": {"type": "checker", "squares": 8, "color_a": [0.9, 0.9, 0.85],
                    "color_b": [0.1, 0.12, 0.2]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "materials": {"glass": {"n": 1.5168}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}],
}
TASK = {"kind": "render", "width": 32, "height": 24, "spp": 2}
TURNTABLE = [[0, 0, -40], [20, 0, -34.64], [34.64, 0, -20]]
# A small round brilliant for the gem task (its camera and environment are the analysis' own).
GEM_SCENE = {
    "camera": {"position": [0, 52, -30], "look_at": [0, -0.8, 0], "up": [0, 1, 0], "fov_deg": 12,
               "width": 16, "height": 16},
    "volume": {"bounds_min": [-5.6, -4.9, -5.6], "bounds_max": [5.6, 2.1, 5.6], "resolution": 32},
    "materials": {"diamond": {"n": {"sellmeier": [0.3306, 4.3356, 0.030625, 0.011236],
                                    "range_nm": [225, 10000]}}},
    "objects": [{"shape": "brilliant", "diameter": 10, "table": 0.57, "crown_deg": 34.5,
                 "pavilion_deg": 40.75, "girdle": 0.02, "facets": 16, "material": "diamond"}],
}
GEM_OPTIONS = {"tilts": [0], "width": 32, "height": 32, "spp": 1}


def sweep_file(folder, vary, scene=SCENE, task=TASK):
    path = os.path.join(folder, "sweep.json")
    with open(path, "w") as f:
        json.dump({"scene": scene, "task": task, "vary": vary}, f)
    return path


def alone(item_scene):
    """The item rendered alone, as a user would: a fresh Scene and Renderer in this process."""
    return eikon.Renderer(eikon.Scene.parse(item_scene)).render(
        progress=False, **{k: v for k, v in TASK.items() if k != "kind"})


def run_cli(args, env=None, **kw):
    return subprocess.run([EIKON, "sweep", *args], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **(env or {})}, **kw)


class LocalSweep(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="eikon-sweep-")
        self.addCleanup(shutil.rmtree, self.dir, True)

    def test_results_equal_serial_runs_and_a_rerun_does_no_work(self):
        out = os.path.join(self.dir, "out")
        trace = os.path.join(self.dir, "trace")
        os.environ["EIKON_SWEEP_TRACE"] = trace
        self.addCleanup(os.environ.pop, "EIKON_SWEEP_TRACE")
        path = sweep_file(self.dir, {"/camera/position": TURNTABLE,
                                     "/objects/0/material": ["glass", "nosuchmaterial"]})
        frame = eikon.sweep(path, out, workers=2, progress=False)
        self.assertEqual(len(frame), 6)
        self.assertEqual(sorted(frame["index"]), list(range(6)))
        bad = frame[frame["/objects/0/material"] == "nosuchmaterial"]
        good = frame[frame["/objects/0/material"] == "glass"]
        self.assertEqual(len(bad), 3)
        for e in bad["error"]:
            self.assertIn("/objects/0/material: unknown material 'nosuchmaterial'", e)
        self.assertTrue(good["error"].isna().all(), list(good["error"]))
        for _, row in good.iterrows():
            scene = json.loads(json.dumps(SCENE))
            scene["camera"]["position"] = json.loads(row["/camera/position"])
            rgb = alone(scene)
            y = rgb @ np.array([0.2126, 0.7152, 0.0722])
            for name, want in (("mean_r", rgb[..., 0].mean()), ("mean_luminance", y.mean()),
                               ("max_luminance", y.max())):
                self.assertLessEqual(abs(row[name] - want), 1e-9 * abs(want), name)
            np.testing.assert_array_equal(eikon.read_exr(os.path.join(out, row["exr"])), rgb)
            self.assertTrue(os.path.isfile(os.path.join(out, row["png"])))
        # The turntable voxelised once per worker: every worker's later items were warm.
        for _, rows in good.groupby("worker"):
            self.assertLessEqual(int((~rows["warm"].astype(bool)).sum()), 1)
        csv = pd.read_csv(os.path.join(out, "results.csv"))
        self.assertEqual(list(csv["index"]), list(frame["index"]))
        # Re-run: nothing starts, nothing is rewritten, the same table.
        started = open(trace).read().count("start")
        stamps = {n: os.stat(os.path.join(out, "items", n)).st_mtime_ns
                  for n in os.listdir(os.path.join(out, "items"))}
        again = eikon.sweep(path, out, workers=2, progress=False)
        self.assertEqual(open(trace).read().count("start"), started)
        self.assertEqual(stamps, {n: os.stat(os.path.join(out, "items", n)).st_mtime_ns
                                  for n in os.listdir(os.path.join(out, "items"))})
        pd.testing.assert_frame_equal(again, frame)

    def test_gem_rows_equal_eikon_gem_alone(self):
        out = os.path.join(self.dir, "out")
        task = {"kind": "gem", **GEM_OPTIONS, "keep_images": True}
        path = sweep_file(self.dir, {"/objects/0/pavilion_deg": [39.5, 42]}, GEM_SCENE, task)
        frame = eikon.sweep(path, out, workers=2, progress=False)
        self.assertEqual(len(frame), 2)
        self.assertTrue(frame["error"].isna().all(), list(frame["error"]))
        for _, row in frame.iterrows():
            scene = json.loads(json.dumps(GEM_SCENE))
            scene["objects"][0]["pavilion_deg"] = float(row["/objects/0/pavilion_deg"])
            want = eikon.gem(eikon.Scene.parse(scene), keep_images=True, **GEM_OPTIONS)
            for name in ("brightness", "fire", "scintillation", "windowing", "extinction",
                         "contrast_change"):
                self.assertLessEqual(abs(row[name] - want[name]), 1e-9 * abs(want[name]), name)
            for name in ("dome_0", "spot_0", "aset", "idealscope", "lightbox"):
                np.testing.assert_array_equal(
                    eikon.read_exr(os.path.join(out, row[name + "_exr"])), want["images"][name])
                self.assertTrue(os.path.isfile(os.path.join(out, row[name + "_png"])))
        # The two pavilions are two stones: the figures differ.
        self.assertNotEqual(frame["brightness"].iloc[0], frame["brightness"].iloc[1])

    @unittest.skipUnless(EIKON, "needs EIKON_BINARY")
    def test_a_worker_killed_mid_item_loses_nothing(self):
        out, trace = os.path.join(self.dir, "out"), os.path.join(self.dir, "trace")
        scene = json.loads(json.dumps(SCENE))
        scene["volume"]["resolution"] = 96  # the first item voxelises for a while: time to kill
        path = sweep_file(self.dir, {"/camera/position": TURNTABLE + [[0, 20, -34.64]]}, scene)
        proc = subprocess.Popen([EIKON, "sweep", path, "-o", out, "--workers", "2"],
                                env={**os.environ, "EIKON_SWEEP_TRACE": trace},
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        victim, key, deadline = None, None, time.monotonic() + 60
        while victim is None and time.monotonic() < deadline and proc.poll() is None:
            lines = open(trace).read().split("\n") if os.path.exists(trace) else []
            started = [ln.split() for ln in lines if ln.startswith("start")]
            ended = {tuple(ln.split()[1:]) for ln in lines if ln.startswith("end")}
            open_items = [(k, int(p)) for _, k, p in started if (k, p) not in ended]
            if open_items:
                key, victim = open_items[0]
                os.kill(victim, signal.SIGKILL)
            time.sleep(0.02)
        self.assertIsNotNone(victim, "no item was seen running")
        _, err = proc.communicate(timeout=120)
        self.assertEqual(proc.returncode, 0, err)
        csv = pd.read_csv(os.path.join(out, "results.csv"))
        self.assertEqual(sorted(csv["index"]), [0, 1, 2, 3])
        self.assertTrue(csv["error"].isna().all(), list(csv["error"]))
        lines = open(trace).read().split("\n")
        redone = [ln.split() for ln in lines if ln.startswith("end " + key)]
        self.assertTrue(redone and all(int(p) != victim for _, _, p in redone), lines)

    @unittest.skipUnless(EIKON, "needs EIKON_BINARY")
    def test_an_existing_scheduler(self):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        address = f"tcp://127.0.0.1:{port}"
        env = {**os.environ, "PYTHONPATH": os.environ["EIKON_PYTHON_DIR"]}
        procs = [subprocess.Popen(["dask-scheduler", "--host", "127.0.0.1", "--port", str(port),
                                   "--no-dashboard"], env=env, stderr=subprocess.DEVNULL),
                 subprocess.Popen(["dask-worker", address, "--nworkers", "1", "--nthreads", "1",
                                   "--no-dashboard", "--name", "w-local"],
                                  env=env, stderr=subprocess.DEVNULL)]
        for p in procs:
            self.addCleanup(p.wait, 30)
            self.addCleanup(p.terminate)
        out = os.path.join(self.dir, "out")
        path = sweep_file(self.dir, {"/camera/position": TURNTABLE[:2]})
        r = run_cli([path, "-o", out, "--scheduler", address])
        self.assertEqual(r.returncode, 0, r.stderr)
        csv = pd.read_csv(os.path.join(out, "results.csv"))
        self.assertEqual(list(csv["worker"]), ["w-local", "w-local"])
        self.assertTrue(csv["error"].isna().all())

    @unittest.skipUnless(EIKON, "needs EIKON_BINARY")
    def test_bad_sweep_files(self):
        cases = [({"/objects/3/material": ["glass"]}, "/vary/~1objects~13~1material: "
                  "/objects has 1 element, no element 3"),
                 ({"/camera/position": []}, "/vary/~1camera~1position: expected a non-empty list"),
                 ({"camera": [1]}, "/vary/camera: 'camera' is not a JSON pointer")]
        for vary, want in cases:
            out = os.path.join(self.dir, "out")
            path = sweep_file(self.dir, vary)
            r = run_cli([path, "-o", out])
            self.assertEqual(r.returncode, 2)
            self.assertEqual(r.stderr.count("\n"), 1, r.stderr)
            self.assertIn(f"{path}: {want}", r.stderr)
            self.assertFalse(os.path.exists(out))
        path = sweep_file(self.dir, {}, task={"kind": "render", "sp": 1})
        r = run_cli([path, "-o", os.path.join(self.dir, "out")])
        self.assertIn(f"{path}: /task/sp: unknown option of the render task", r.stderr)
        path = sweep_file(self.dir, {}, task={"kind": "gem", "spp": "4"})
        r = run_cli([path, "-o", os.path.join(self.dir, "out")])
        self.assertEqual((r.returncode, r.stderr.count("\n")), (2, 1), r.stderr)
        self.assertIn(f"{path}: /task/spp: expected int, got '4'", r.stderr)
        with open(path, "w") as f:
            f.write('{"scene": 1,')
        r = run_cli([path, "-o", os.path.join(self.dir, "out")])
        self.assertIn(f"eikon: error: {path}: line 1:", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.dir, "out")))


if __name__ == "__main__":
    unittest.main()
