"""Renderer.render(modes=...) is `eikon render --modes` (docs/viewer.md "Modes").

Unpolarised light splits at a crystal into the ordinary and the extraordinary mode, each carrying
half of it: modes="both" is ½·(o + e), "o" and "e" march one mode alone at the whole of the
light. So o + e = 2·both within float rounding (the C++ ModeSelection tests hold both twins to it,
tests/core/render/mode_selection_test.cpp), and calcite separates the modes (else the identity
would hold for a module that ignored the keyword). A bad value is one ValueError, in the CLI's
words. Run by CTest (python.render_modes) with EIKON_BINARY and EIKON_PYTHON_DIR.
"""
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]
SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RHOMB = os.path.join(SOURCE, "scenes", "calcite_rhomb.json")


class RenderModes(unittest.TestCase):
    def test_o_plus_e_is_twice_both_on_calcite_rhomb(self):
        scene = eikon.Scene.load(RHOMB)
        self.assertTrue(scene.any_uniaxial)
        volume = scene.volume  # as the C++ test: 96 voxels a side are enough to split the modes
        volume.resolution = 96
        scene.volume = volume
        r = eikon.Renderer(scene)
        for wavelengths in (0, 4):
            kw = dict(width=32, height=24, wavelengths=wavelengths, light=False)
            both, o, e = (r.render(modes=m, **kw) for m in ("both", "o", "e"))
            self.assertEqual(both.shape, (24, 32, 3))
            tolerance = 1e-5 * (np.abs(o) + np.abs(e) + 2 * np.abs(both)) + 1e-6
            worst = float((np.abs(o + e - 2 * both) / tolerance).max())
            apart = float(np.abs(o - e).max())
            print(f"{wavelengths} wavelengths: |o + e - 2 both| <= {worst:.3g} of the tolerance; "
                  f"max |o - e| {apart:.3g}")
            self.assertLessEqual(worst, 1.0, wavelengths)
            self.assertGreater(apart, 0.05, f"{wavelengths} wavelengths: the modes do not differ")
            # The default is both.
            self.assertEqual(float(np.abs(r.render(**kw) - both).max()), 0.0)

    def test_a_bad_value_is_one_error_in_the_cli_words(self):
        scene = eikon.Scene.load(RHOMB)
        n0 = eikon.voxelize_count()
        for bad in ("oe", "", "O"):
            with self.assertRaises(ValueError) as cm:
                eikon.render(scene, modes=bad)
            self.assertEqual(str(cm.exception), f"modes must be o, e, fast, slow or both, got '{bad}'")
        with self.assertRaises(TypeError):
            eikon.render(scene, modes=1)
        self.assertEqual(eikon.voxelize_count(), n0)  # refused before anything is voxelised
        with tempfile.TemporaryDirectory() as tmp:
            r = subprocess.run([EIKON, "render", RHOMB, "-o", os.path.join(tmp, "x.exr"),
                                "--modes", "oe"], capture_output=True, text=True, timeout=120)
        self.assertNotEqual(r.returncode, 0)
        self.assertEqual(r.stderr.strip().splitlines(),
                         ["eikon: error: --modes must be o, e, fast, slow or both, got 'oe'"])


if __name__ == "__main__":
    unittest.main()
