"""The same scene renders the same from Python and from `eikon render` by default.

Run by CTest (python.render_defaults) with EIKON_BINARY (the CLI) and EIKON_PYTHON_DIR (the
built module). Each case writes a small scene, renders it with the CLI's defaults (`eikon render
SCENE -o X.exr`) and with Python's (`eikon.render(scene)`) and compares the images: both run
the same GPU march over the same volume, so they agree to float rounding (tolerance 1e-5 of a
pixel value ~0.1–1; the RGB-versus-16-wavelengths difference the defaults used to make is
~0.1–1). Also checks that module-level render() voxelises a scene once (eikon.voxelize_count()).
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]

# An N-BK7 (Sellmeier, dispersive) sphere over a checkerboard: 16 wavelengths by default.
DISPERSIVE = {
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 40, "height": 30},
    "environment": {"type": "checker", "squares": 8, "color_a": [0.9, 0.9, 0.85], "color_b": [0.1, 0.12, 0.2]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                                 0.00600069867, 0.0200179144, 103.560653]}}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}],
}

# scenes/caustic_sphere.json made small: a ball lens over a diffuse floor under a directional
# light (constant index: RGB); unlit, the floor is black.
LIT = {
    "camera": {"position": [0, 20, -46], "look_at": [0, -5, 0], "up": [0, 1, 0], "fov_deg": 34,
               "width": 32, "height": 24},
    "environment": {"type": "constant", "radiance": [0.03, 0.035, 0.05]},
    "volume": {"bounds_min": [-14, -9.5, -14], "bounds_max": [14, 9, 14], "resolution": 28},
    "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1.0, "opacity": 1, "albedo": 0.8}},
    "objects": [{"shape": "box", "center": [0, -8, 0], "size": [26.5, 1.5, 26.5], "material": "floor"},
                {"shape": "sphere", "center": [0, 2, 0], "radius": 6, "material": "glass"}],
    "lights": [{"type": "directional", "direction": [0.25, -1, 0.15], "irradiance": 3.0}],
}


class RenderDefaults(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        eikon.clear_cache()

    def tearDown(self):
        self.tmp.cleanup()

    def cli_render(self, scene_dict, name, *args, env=None):
        path = os.path.join(self.dir, name + ".json")
        with open(path, "w") as f:
            json.dump(scene_dict, f)
        out = os.path.join(self.dir, name + ".exr")
        run_env = dict(os.environ, EIKON_CACHE_DIR=os.path.join(self.dir, "cache"), **(env or {}))
        r = subprocess.run([EIKON, "render", path, "-o", out, "-q", *args], capture_output=True, text=True,
                           env=run_env, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        return path, eikon.read_exr(out)

    def test_dispersive_scene_renders_as_the_cli(self):
        path, cli = self.cli_render(DISPERSIVE, "dispersive")
        scene = eikon.Scene.load(path)
        self.assertTrue(scene.any_dispersive)
        py = eikon.render(scene)
        self.assertEqual(py.shape, cli.shape)
        self.assertGreater(float(cli.max()), 0.1)
        self.assertLess(float(np.abs(py - cli).max()), 1e-5)
        # The old Python default (RGB at the d line) is far from the CLI's 16 wavelengths: the test
        # would see it.
        rgb = eikon.render(scene, wavelengths=0)
        self.assertGreater(float(np.abs(rgb - cli).max()), 1e-2)

    def test_lit_scene_renders_as_the_cli(self):
        # The CLI simulates the light and fills its cache; Python simulates it again itself (no
        # cache), on the twin the CLI picks, then reads the CLI's cache entry.
        path, cli = self.cli_render(LIT, "lit")
        scene = eikon.Scene.load(path)
        py = eikon.render(scene, light_cache=False)
        self.assertEqual(py.shape, cli.shape)
        self.assertLess(float(np.abs(py - cli).max()), 1e-5)
        unlit = eikon.Renderer(scene).render(light=False)
        self.assertGreater(float(np.abs(unlit - cli).max()), 1e-2)  # the lit floor and caustic
        cache = os.path.join(self.dir, "cache")
        self.assertTrue(any(f.startswith("light-") for f in os.listdir(cache)), os.listdir(cache))
        eikon.clear_cache()
        cached = eikon.render(eikon.Scene.load(path), light_cache=cache)
        self.assertLess(float(np.abs(cached - cli).max()), 1e-5)

    def test_simulate_light_reports_the_flux_reflected_at_sharp_interfaces(self):
        # Sharp interfaces: the light follows the scene's "interfaces" on both twins, and its
        # Fresnel reflections as reflected wavefronts (four generations by default); it reports
        # the reflected flux not followed, less than the least the light would lose without
        # them, the normal-incidence loss of the lit disc's two passes, 1 - (1 - R0)^2 = 0.0784,
        # times the disc's share pi R^2 / A of the light (A: the box's area projected along the
        # light); a smoothed scene reflects nothing.
        d = np.array([0.25, -1.0, 0.15]) / np.linalg.norm([0.25, -1.0, 0.15])
        area = abs(d[0]) * 18.5 * 28 + abs(d[1]) * 28 * 28 + abs(d[2]) * 28 * 18.5
        disc = np.pi * 6.0 ** 2 / area
        for device in ("cpu", "gpu"):
            s = eikon.Renderer(eikon.Scene.parse(LIT)).simulate_light(device=device, caustics="kill")
            share = s["flux_reflected"] / s["flux_emitted"]
            self.assertLess(share, 0.0784 * disc, device)
        smoothed = dict(LIT, interfaces="smoothed")
        s = eikon.Renderer(eikon.Scene.parse(smoothed)).simulate_light(device="cpu", caustics="kill")
        self.assertEqual(s["flux_reflected"], 0.0)

    def test_module_level_calls_voxelise_once(self):
        scene = eikon.Scene.parse(DISPERSIVE)
        n0 = eikon.voxelize_count()
        a = eikon.render(scene, width=16, height=12)
        self.assertEqual(eikon.voxelize_count(), n0 + 1)
        b = eikon.render(scene, width=16, height=12)
        eikon.trace(scene, [0, 0, -20], [0, 0, 1])
        self.assertEqual(eikon.voxelize_count(), n0 + 1)  # reused
        np.testing.assert_array_equal(a, b)
        scene.camera.position = [0, 5, -40]  # a camera edit needs no new volume
        c = eikon.render(scene, width=16, height=12)
        self.assertEqual(eikon.voxelize_count(), n0 + 1)
        self.assertGreater(float(np.abs(c - a).max()), 1e-3)
        vol = scene.volume
        vol.resolution = 24  # a volume edit does
        scene.volume = vol
        eikon.render(scene, width=16, height=12)
        self.assertEqual(eikon.voxelize_count(), n0 + 2)
        other = eikon.Scene.parse(DISPERSIVE)  # another Scene object does
        eikon.render(other, width=16, height=12)
        self.assertEqual(eikon.voxelize_count(), n0 + 3)


if __name__ == "__main__":
    unittest.main(verbosity=2)
