"""Renderer.render(layers="stokes") (docs/polarisation.md "Polarised renders"): a polarised render's
Stokes layers through the module, against closed forms, on the CPU twin (device="cpu"):

  - a sheet along x with the camera's analyser at 60°: S0 = ½cos²60° = 0.125 of the unit sky, linear
    at −60° in the pixel frame stokesBasis(−v) (x̂ = +x, ŷ = −y for a camera looking along +z):
    S1 = 0.125 cos(−120°), S2 = 0.125 sin(−120°), S3 = 0 (1e-4: a 0.2° field);
  - rgb is S0; the dict carries stokes_frame;
  - polarised=True in a scene without sheets returns the plain (H, W, 3) image of the sky (S0 = 1);
  - "stokes" with "spectral" raises ValueError.
Run by CTest (python.polarised_render) with EIKON_PYTHON_DIR.
"""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402


def scene(objects, analyzer=None):
    camera = {"position": [0, 0, -40], "look_at": [0, 0, 0], "fov_deg": 0.2, "width": 6,
              "height": 4}
    if analyzer is not None:
        camera["analyzer"] = analyzer
    return eikon.Scene.parse({
        "camera": camera, "environment": {"type": "constant", "radiance": 1},
        "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 24},
        "materials": {"glass": {"n": 1.5}},
        "objects": [{"shape": "sphere", "center": [3, 3, 3], "radius": 1, "material": "glass"}]
        + objects})


SHEET_X = {"shape": "polarizer", "center": [0, 0, 20], "normal": [0, 0, 1],
           "transmission_axis": [1, 0, 0], "size": [40, 40]}


class PolarisedRender(unittest.TestCase):
    def test_analyser_and_sheet_give_malus_in_the_pixel_frame(self):
        r = math.radians(60)
        out = eikon.Renderer(scene([SHEET_X], [math.cos(r), math.sin(r), 0])).render(
            layers="stokes", device="cpu", wavelengths=0)
        s = out["stokes"]
        self.assertEqual(s.shape, (4, 6, 4, 3))
        want = 0.5 * math.cos(r) ** 2
        np.testing.assert_allclose(s[..., 0, :], want, atol=1e-4)
        np.testing.assert_allclose(s[..., 1, :], want * math.cos(-2 * r), atol=1e-4)
        np.testing.assert_allclose(s[..., 2, :], want * math.sin(-2 * r), atol=1e-4)
        np.testing.assert_allclose(s[..., 3, :], 0.0, atol=1e-6)
        np.testing.assert_array_equal(out["rgb"], s[..., 0, :])
        self.assertIn("stokes_basis(-v)", out["stokes_frame"])

    def test_polarised_without_sheets_sees_the_sky(self):
        img = eikon.Renderer(scene([])).render(polarised=True, device="cpu", wavelengths=0)
        self.assertEqual(img.shape, (4, 6, 3))
        np.testing.assert_allclose(img, 1.0, atol=1e-6)

    def test_stokes_with_spectral_layers_is_refused(self):
        with self.assertRaises(ValueError):
            eikon.Renderer(scene([SHEET_X])).render(layers="stokes,spectral", wavelengths=4,
                                                    device="cpu")


if __name__ == "__main__":
    unittest.main()
