"""Renderer.render(layers=...) returns the layers of `eikon render --layers` as numpy arrays.

Run by CTest (python.render_layers) with EIKON_PYTHON_DIR (the built module). Closed forms: the
spectral channels integrated bin by bin with the CIE 1931 functions give the RGB returned with
them, within 1e-4 relative (checked here through a flat spectrum: a grey sky seen directly is the
grey level in every bin and in R, G, B); the o and e layers add up to the RGB and e is zero
without a crystal; bin centres are 380 + (k + 1/2)·400/N nm; a bad layers value raises. The aov
layer's depth, point and normal of a pixel-centre ray are the analytic ray–sphere intersection's
(sharp interfaces: 1e-4 mm, 1e-5), its object id the sphere's (0), and a pixel that sees the sky
has depth inf and object -1; both devices agree.
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

    def test_aov_as_arrays(self):
        for device in ("gpu", "cpu"):
            out = self.renderer.render(wavelengths=0, layers="aov", device=device)
            self.assertEqual(set(out.keys()),
                             {"rgb", "depth", "point", "normal", "object_id", "steps"})
            self.assertEqual(out["depth"].shape, (12, 16))
            self.assertEqual(out["normal"].shape, (12, 16, 3))
            self.assertEqual(out["object_id"].dtype, np.int32)
            # Pixel (x=7, y=5)'s centre ray (the pinhole model of the scene camera) meets the
            # sphere |x| = 5 at t = -b - sqrt(b² - |o|² + r²).
            t, aspect = np.tan(np.radians(15.0)), 16 / 12
            u = ((7 + 0.5) / 16 * 2 - 1) * t * aspect
            v = (1 - (5 + 0.5) / 12 * 2) * t
            right = np.cross([0, 0, 1.0], [0, 1.0, 0])
            d = np.array([0, 0, 1.0]) + u * right + v * np.array([0, 1.0, 0])
            d /= np.linalg.norm(d)
            o = np.array([0, 0, -40.0])
            b = o @ d
            hit = -b - np.sqrt(b * b - o @ o + 25.0)
            p = o + hit * d
            self.assertAlmostEqual(float(out["depth"][5, 7]), hit, delta=1e-4)
            np.testing.assert_allclose(out["point"][5, 7], p, atol=1e-4)
            np.testing.assert_allclose(out["normal"][5, 7], p / 5.0, atol=1e-5)
            self.assertEqual(int(out["object_id"][5, 7]), 0)
            self.assertGreaterEqual(float(out["steps"][5, 7]), 2.0)
            self.assertTrue(np.isinf(out["depth"][0, 0]))
            self.assertEqual(int(out["object_id"][0, 0]), -1)

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
