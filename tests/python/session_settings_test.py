"""Python and `eikon render`/`eikon trace` refuse the same settings with the same words.

Both front ends run the checks of eikon::Session (core/session/session.h): the CLI prints
"eikon: error: --width must be in [1, 16384], got 0", Python raises ValueError("width must be in
[1, 16384], got 0"), naming the setting its own way (`--light-splat` is `splat=`, `--step` is
`march.step_voxels`, `--dir` is `direction`). Every case is refused before anything is voxelised
(eikon.voxelize_count() stays 0). Run by CTest (python.session_settings) with EIKON_BINARY and
EIKON_PYTHON_DIR.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]

SCENE = {
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 8, "height": 6},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 4, "material": "glass"}],
}


class SessionSettings(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.tmp.name, "scene.json")
        with open(self.path, "w") as f:
            json.dump(SCENE, f)
        self.scene = eikon.Scene.load(self.path)
        eikon.clear_cache()

    def tearDown(self):
        self.tmp.cleanup()

    def cli_error(self, *args):
        r = subprocess.run([EIKON, *args], capture_output=True, text=True, timeout=120)
        self.assertNotEqual(r.returncode, 0)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        return lines[0]

    def py_error(self, call):
        with self.assertRaises(ValueError) as cm:
            call()
        return str(cm.exception)

    def same(self, cli_args, cli_option, call, py_name, complaint):
        out = os.path.join(self.tmp.name, "x.exr")
        cli = self.cli_error(cli_args[0], self.path, *(["-o", out] if cli_args[0] == "render" else []),
                             *cli_args[1:])
        self.assertTrue(cli.endswith(cli_option + " " + complaint), cli)
        self.assertEqual(self.py_error(call), py_name + " " + complaint)
        self.assertFalse(os.path.exists(out))

    def test_render_sizes(self):
        r = eikon.Renderer(self.scene)
        self.same(["render", "--width", "-3"], "--width", lambda: r.render(width=-3), "width",
                  "must be in [1, 16384], got -3")
        self.same(["render", "--spp", "0"], "--spp", lambda: eikon.render(self.scene, spp=0), "spp",
                  "must be in [1, 4096], got 0")
        self.same(["render", "--wavelengths", "300"], "--wavelengths", lambda: r.render(wavelengths=300),
                  "wavelengths", "must be in [0, 256], got 300")
        self.same(["render", "--step", "5"], "--step",
                  lambda: r.render(march=eikon.MarchSettings(step_voxels=5)), "march.step_voxels",
                  "must be in (0, 4] voxels")
        # The twin (`--device`, Python's device=): auto (the default), gpu or cpu.
        self.same(["render", "--device", "tpu"], "--device", lambda: r.render(device="tpu"),
                  "device", "must be auto, gpu or cpu, got 'tpu'")
        self.assertEqual(eikon.voxelize_count(), 0)

    def test_values_that_crashed_are_refused(self):
        # None for a scene was a segmentation fault; smoothing_voxels=nan and threads=100000
        # crashed or aborted; wavelength_nm=nan rendered NaN pixels.
        with self.assertRaises(TypeError):
            eikon.Renderer(None)
        with self.assertRaises(TypeError):
            eikon.render(None)
        r = eikon.Renderer(self.scene)
        for bad in (float("nan"), 1e30, -1):
            self.assertIn("must be in [0, 8] voxels",
                          self.py_error(lambda: r.simulate_light(smoothing_voxels=bad)))
        self.same(["render", "--threads", "100000"], "--threads",
                  lambda: r.render(device="cpu", threads=100000), "threads",
                  "must be in [1, 1024], or 0 for all cores")
        for bad in (float("nan"), -5, 0, float("inf")):
            self.assertIn("must be in [100, 10000] nm",
                          self.py_error(lambda: r.render(wavelength_nm=bad)))
        self.assertEqual(eikon.voxelize_count(), 0)

    def test_interface_threshold_is_refused_alike_by_both_twins(self):
        # The GPU twin alone checked it: a NaN or negative threshold rendered on the CPU twin.
        # Both refuse it before any voxelising, as the other settings.
        r = eikon.Renderer(self.scene)
        for bad in (float("nan"), -1.0, 0.0, float("inf")):
            for device in ("cpu", "gpu"):
                with self.assertRaisesRegex(ValueError,
                                            "interface threshold must be a finite number > 0"):
                    r.render(width=8, height=6, device=device,
                             march=eikon.MarchSettings(interface_threshold=bad))
        self.assertEqual(eikon.voxelize_count(), 0)

    def test_edited_camera_and_volume_are_checked_as_a_scene_file_is(self):
        # Scene.camera and Scene.volume are writable: a resolution of 0 gave a voxel of inf mm,
        # a width of -5 a buffer of 17592186044415 MiB. The session checks them as parsing does.
        self.scene.volume.resolution = 0
        with self.assertRaisesRegex(RuntimeError, "/volume/resolution: must be an integer in"):
            eikon.Renderer(self.scene).grid()
        self.scene.volume.resolution = 16
        self.scene.camera.width = -5
        with self.assertRaisesRegex(RuntimeError, "/camera/width: must be an integer in"):
            eikon.Renderer(self.scene).render()
        self.scene.camera.width = 8
        self.scene.camera.fov_deg = float("nan")
        with self.assertRaisesRegex(RuntimeError, "/camera/fov_deg"):
            eikon.Renderer(self.scene).render()

    def test_light_settings(self):
        r = eikon.Renderer(self.scene)
        self.same(["render", "--light-splat", "max"], "--light-splat", lambda: r.simulate_light(splat="max"),
                  "splat", "must be accumulate or highest, got 'max'")
        self.same(["render", "--caustics", "stop"], "--caustics", lambda: r.simulate_light(caustics="stop"),
                  "caustics", "must be pass or kill, got 'stop'")
        self.same(["render", "--light-step", "3"], "--light-step", lambda: r.simulate_light(step_voxels=3),
                  "step_voxels", "must be in (0, 2] voxels, or 0 for the default (0.5)")
        self.assertEqual(eikon.voxelize_count(), 0)

    def test_trace_settings(self):
        r = eikon.Renderer(self.scene)
        self.same(["trace", "--origin", "0,0,-7", "--dir", "0,0,0"], "--dir",
                  lambda: r.trace([0, 0, -7], [0, 0, 0]), "direction", "must be a non-zero vector")
        self.same(["trace", "--origin", "0,0,-7", "--dir", "0,0,1", "--wavelength", "50"], "--wavelength",
                  lambda: eikon.trace(self.scene, [0, 0, -7], [0, 0, 1], wavelength_nm=50), "wavelength_nm",
                  "must be in [100, 10000] nm")
        self.assertEqual(self.py_error(lambda: eikon.MarchSettings(integrator="verlet")),
                         "integrator must be euler, midpoint or rk4")
        self.assertEqual(eikon.voxelize_count(), 0)


if __name__ == "__main__":
    unittest.main()
