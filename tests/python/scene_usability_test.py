"""A scene's "render" is the default of Python's render as of `eikon render`, the material
library forgives case, spaces and underscores and answers a misspelt name with the closest ones,
and its biaxial materials load and make objects (sharp interfaces only).

Run by CTest (python.scene_usability) with EIKON_BINARY (the CLI) and EIKON_PYTHON_DIR (the
built module). The CLI and Python run the same GPU march, so their images agree to float rounding
(1e-5); spp=2 against spp=3 differ by the jitter of a sample (> 1e-3 at the sphere's edge).
"""
import copy
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
    "render": {"spp": 3, "wavelengths": 0},
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 40, "height": 30},
    "environment": {"type": "checker", "squares": 8},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 32},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "N-BK7"}],
}


class SceneUsability(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = self.tmp.name
        eikon.clear_cache()

    def tearDown(self):
        self.tmp.cleanup()

    def test_render_settings_of_the_scene_are_the_defaults(self):
        path = os.path.join(self.dir, "hinted.json")
        with open(path, "w") as f:
            json.dump(SCENE, f)
        scene = eikon.Scene.load(path)
        self.assertEqual(scene.render, {"spp": 3, "wavelengths": 0, "exposure": None})
        out = os.path.join(self.dir, "hinted.exr")
        r = subprocess.run([EIKON, "render", path, "-o", out, "-q"], capture_output=True, text=True,
                           env=dict(os.environ, EIKON_CACHE_DIR=os.path.join(self.dir, "cache")),
                           timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("RGB, 3 spp", r.stdout)
        cli = eikon.read_exr(out)
        py = eikon.render(scene)
        self.assertLess(float(np.abs(py - cli).max()), 1e-5)
        explicit = eikon.render(scene, spp=3, wavelengths=0)
        self.assertLess(float(np.abs(py - explicit).max()), 1e-5)
        other = eikon.render(scene, spp=2)  # the argument wins
        self.assertGreater(float(np.abs(other - py).max()), 1e-3)
        plain = copy.deepcopy(SCENE)
        del plain["render"]
        self.assertEqual(eikon.Scene.parse(plain).render,
                         {"spp": None, "wavelengths": None, "exposure": None})

    def test_bad_render_settings_name_their_path(self):
        bad = copy.deepcopy(SCENE)
        bad["render"] = {"spp": 0}
        with self.assertRaisesRegex(Exception, r"/render/spp: "):
            eikon.Scene.parse(bad, "bad.json")

    def test_material_names_are_forgiven_and_misspellings_answered(self):
        n_d = eikon.load_material("fused-silica").n.index(587.5618)
        for name in ("fused silica", "Fused_Silica", "FUSED-SILICA"):
            self.assertEqual(eikon.load_material(name).n.index(587.5618), n_d, name)
        self.assertAlmostEqual(eikon.load_material("Diamond").n.index(587.5618), 2.4175, delta=2e-3)
        with self.assertRaises(ValueError) as caught:
            eikon.load_material("N-BK8")
        message = str(caught.exception)
        self.assertIn("did you mean 'N-BK7'?", message)
        self.assertIn("ruby", message)

    def test_biaxial_materials_load_and_make_objects_with_sharp_interfaces(self):
        # docs/scene-format.md "Biaxial materials": listed with their principal indices and axes;
        # an object of one renders its fast and slow modes, with sharp interfaces only.
        topaz = eikon.load_material("topaz")
        self.assertTrue(topaz.biaxial)
        self.assertFalse(topaz.uniaxial)
        self.assertIn("(biaxial)", repr(topaz))
        a, b, g = (topaz.n_alpha.index(587.6), topaz.n_beta.index(587.6),
                   topaz.n_gamma.index(587.6))
        self.assertLess(a, b)
        self.assertLess(b, g)
        self.assertAlmostEqual(float(np.dot(topaz.alpha_axis, topaz.gamma_axis)), 0.0, delta=1e-12)
        good = copy.deepcopy(SCENE)
        good["objects"][0]["material"] = "topaz"
        self.assertEqual(eikon.modes_traced(eikon.Scene.parse(good, "good.json")),
                         ["fast", "slow"])
        bad = copy.deepcopy(good)
        bad["interfaces"] = "smoothed"
        with self.assertRaisesRegex(Exception, r"/objects/0/material: biaxial material 'topaz': "
                                               r"\"interfaces\": \"smoothed\" is not yet"):
            eikon.Scene.parse(bad, "bad.json")


if __name__ == "__main__":
    unittest.main()
