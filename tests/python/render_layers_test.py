"""Renderer.render(layers=...) returns the layers of `eikon render --layers` as numpy arrays.

Run by CTest (python.render_layers) with EIKON_PYTHON_DIR (the built module). Closed forms: the
spectral channels integrated bin by bin with the CIE 1931 functions give the RGB returned with
them, within 1e-4 relative (checked here through a flat spectrum: a grey sky seen directly is the
grey level in every bin and in R, G, B); the o and e layers add up to the RGB and e is zero
without a crystal; bin centres are 380 + (k + 1/2)·400/N nm; a bad layers value raises.
"""
import os
import sys
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

SCENE = {
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 16, "height": 12},
    "environment": {"type": "constant", "radiance": [0.5, 0.5, 0.5]},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 24},
    "materials": {"glass": {"n": {"sellmeier": [1.03961212, 0.231792344, 1.01046945,
                                                 0.00600069867, 0.0200179144, 103.560653]}}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 5, "material": "glass"}],
}


class RenderLayers(unittest.TestCase):
    def setUp(self):
        self.renderer = eikon.Renderer(eikon.Scene.parse(SCENE))

    def test_layers_as_arrays(self):
        out = self.renderer.render(wavelengths=4, layers="spectral,modes")
        self.assertEqual(set(out.keys()), {"rgb", "spectral", "wavelengths_nm", "o", "e"})
        self.assertEqual(out["rgb"].shape, (12, 16, 3))
        self.assertEqual(out["spectral"].shape, (12, 16, 4))
        np.testing.assert_allclose(out["wavelengths_nm"], [430, 530, 630, 730])
        # The corner pixel sees the grey sky: flat 0.5 in every bin and in R, G, B.
        np.testing.assert_allclose(out["spectral"][0, 0], 0.5, atol=1e-6)
        np.testing.assert_allclose(out["rgb"][0, 0], 0.5, atol=1e-5)
        np.testing.assert_allclose(out["o"] + out["e"], out["rgb"], atol=1e-5)
        self.assertEqual(float(np.abs(out["e"]).max()), 0.0)

    def test_plain_render_is_still_an_array(self):
        img = self.renderer.render(wavelengths=4)
        self.assertEqual(img.shape, (12, 16, 3))

    def test_bad_layers_raise(self):
        with self.assertRaises(ValueError) as e:
            self.renderer.render(wavelengths=4, layers="spectral,colour")
        self.assertIn("colour", str(e.exception))
        with self.assertRaises(ValueError):
            self.renderer.render(wavelengths=0, layers="spectral")


if __name__ == "__main__":
    unittest.main()
