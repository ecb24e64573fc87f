"""eikon.gem is `eikon gem`: the same figures for the same arguments, the same refusals.

Run by CTest (python.gem) with EIKON_BINARY and EIKON_PYTHON_DIR. A small round brilliant in
diamond (32³ voxels), 2 tilts, 32x32, 1 spp: eikon.gem's top-level figures and per_tilt equal
`eikon gem --json`'s for the same arguments (the JSON prints 17 significant digits, so to 1e-12
relative: the same analysis on the same CPU twin, nothing random between the runs); with
keep_images the pictures are (H, W, 3) float32 and the scene passed in keeps its camera; a bad
argument is a ValueError with the CLI's words.
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
SCENE = {
    "camera": {"position": [0, 51.96, -30], "look_at": [0, -0.8, 0], "up": [0, 1, 0],
               "fov_deg": 12, "width": 16, "height": 16},
    "volume": {"bounds_min": [-5.6, -4.9, -5.6], "bounds_max": [5.6, 2.1, 5.6], "resolution": 32},
    "materials": {"diamond": {"n": {"sellmeier": [0.3306, 4.3356, 0.030625, 0.011236],
                                    "range_nm": [225, 10000]}}},
    "objects": [{"shape": "brilliant", "diameter": 10, "table": 0.57, "crown_deg": 34.5,
                 "pavilion_deg": 40.75, "girdle": 0.02, "facets": 16, "material": "diamond"}],
}
ARGS = {"tilts": [-10, 0], "width": 32, "height": 32, "spp": 1}
FIGURES = ("brightness", "fire", "scintillation", "windowing", "extinction", "contrast_change")


class Gem(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)
        self.path = os.path.join(self.tmp.name, "stone.json")
        with open(self.path, "w") as f:
            json.dump(SCENE, f)

    def cli(self, *args):
        return subprocess.run([EIKON, "gem", self.path, *args], capture_output=True, text=True,
                              timeout=300)

    def test_figures_equal_the_cli_json(self):
        scene = eikon.Scene.load(self.path)
        camera = scene.camera.position.copy()
        g = eikon.gem(scene, keep_images=True, **ARGS)
        r = self.cli("--tilts", "-10,0", "--width", "32", "--height", "32", "--spp", "1",
                     "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        want = json.loads(r.stdout)
        for name in FIGURES:
            self.assertIsInstance(g[name], float, name)
            self.assertLessEqual(abs(g[name] - want[name]), 1e-12 * abs(want[name]), name)
        self.assertEqual(g["object"], want["object"])
        self.assertEqual(len(g["per_tilt"]), 2)
        for mine, theirs in zip(g["per_tilt"], want["per_tilt"]):
            self.assertEqual(set(mine), set(theirs))
            for key, value in theirs.items():
                self.assertLessEqual(abs(mine[key] - value), 1e-12 * abs(value), key)
        self.assertGreater(g["brightness"], 0.0)
        self.assertEqual(sorted(g["images"]), ["aset", "dome_0", "dome_1", "idealscope",
                                               "lightbox", "spot_0", "spot_1"])
        for name, image in g["images"].items():
            self.assertEqual((image.shape, image.dtype), ((32, 32, 3), np.float32), name)
            self.assertTrue(np.isfinite(image).all(), name)
        np.testing.assert_array_equal(scene.camera.position, camera)  # the caller's scene
        self.assertNotIn("images", eikon.gem(scene, **ARGS))

    def test_seed_is_the_clis(self):
        # seed shifts the pixel grid as --seed does: the same figures as the command's, others
        # than seed 0's.
        scene = eikon.Scene.load(self.path)
        g = eikon.gem(scene, seed=5, **ARGS)
        r = self.cli("--tilts", "-10,0", "--width", "32", "--height", "32", "--spp", "1",
                     "--json", "--seed", "5")
        self.assertEqual(r.returncode, 0, r.stderr)
        want = json.loads(r.stdout)
        for name in FIGURES:
            self.assertLessEqual(abs(g[name] - want[name]), 1e-12 * abs(want[name]), name)
        self.assertNotEqual(g["brightness"], eikon.gem(scene, **ARGS)["brightness"])

    def test_bad_arguments_are_the_clis_refusals(self):
        scene = eikon.Scene.load(self.path)
        cases = [({"width": 8}, ("--width", "8"), "width must be in [16, 2048], got 8"),
                 ({"spp": 0}, ("--spp", "0"), "spp must be in [1, 256], got 0"),
                 ({"tilts": "-90:0:10"}, ("--tilts", "-90:0:10"), "tilts must be FROM:TO:STEP"),
                 ({"seed": -1}, ("--seed", "-1"), "seed must be in [0, 4294967295], got -1")]
        for kw, args, words in cases:
            with self.assertRaises(ValueError) as cm:
                eikon.gem(scene, **kw)
            self.assertIn(words, str(cm.exception))
            r = self.cli(*args)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--" + str(cm.exception), r.stderr)
        with self.assertRaises(ValueError) as cm:
            eikon.gem(scene, tilts=[0, 61])
        self.assertEqual(str(cm.exception), "tilts must be in [-60, 60] degrees, got 61")
        with self.assertRaises(ValueError) as cm:
            eikon.gem(scene, object=3)
        self.assertIn("object 3 is not in the scene's 1 objects", str(cm.exception))


if __name__ == "__main__":
    unittest.main()
