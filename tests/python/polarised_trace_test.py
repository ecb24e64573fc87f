"""eikon.trace_polarised (docs/polarisation.md): the Stokes vector leaving a scene through the
module, from both twins, against closed forms, and the same numbers as `eikon trace --stokes`.

  - Malus: sheets at 0° and 60° pass ½cos²60° = 0.125 of unpolarised light, linear at 60°
    (tolerance 1e-5: the sheet axes are float32 on the GPU);
  - a 31¼-wave quartz plate with its axis at 45° turns x-polarised light left circular,
    S3/S0 ≤ −0.999;
  - `eikon trace --stokes 1,1,0,0 --json --reference` prints the module's CPU stokes_out (1e-12);
  - bad input (three Stokes numbers, S0 ≤ 0, DoP > 1, unknown device) raises ValueError;
  - nine polariser sheets on the GPU twin (which takes 8) raise RuntimeError naming the 9th.
Run by CTest (python.polarised_trace) with EIKON_BINARY and EIKON_PYTHON_DIR.
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]
QUARTZ_DN = 0.009100044  # n_e − n_o of materials/quartz.json at 589.2938 nm (Ghosh's Sellmeier)


def scene_dict(objects):
    return {"environment": {"type": "constant", "radiance": 1},
            "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 32},
            "materials": {"glass": {"n": 1.5}}, "objects": objects}


def sheet(z, deg):
    r = math.radians(deg)
    return {"shape": "polarizer", "center": [0, 0, z], "normal": [0, 0, 1],
            "transmission_axis": [math.cos(r), math.sin(r), 0], "size": [20, 20]}


ASIDE = {"shape": "sphere", "center": [2, 2, 2], "radius": 1, "material": "glass"}


class PolarisedTrace(unittest.TestCase):
    def test_malus_on_both_twins(self):
        sc = eikon.Scene.parse(scene_dict([sheet(-8, 0), sheet(8, 60), ASIDE]))
        r = eikon.Renderer(sc)
        for device in ["cpu", "gpu"]:
            t = r.trace_polarised([0, 0, -20], [0, 0, 1], 550.0, device=device)
            s = t["stokes_out"]
            self.assertIsInstance(s, np.ndarray)
            self.assertEqual(s.shape, (4,))
            want = 0.125 * np.array([1, math.cos(math.radians(120)), math.sin(math.radians(120)), 0])
            np.testing.assert_allclose(s, want, atol=1e-5, err_msg=device)
            self.assertEqual(len(t["beams"]), 1)
            self.assertEqual(t["beams"][0]["modes"], "-")
            self.assertFalse(t["truncated"])

    def test_quarter_wave_plate_and_the_cli_agree(self):
        th = 31.25 * 589.2938e-6 / QUARTZ_DN
        d = scene_dict([{"shape": "box", "center": [0, 0, 0], "size": [9, 9, th],
                         "material": "quartz", "optic_axis": [0.7071067811865476, 0.7071067811865476, 0]}])
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "qwp.json")
            with open(path, "w") as f:
                json.dump(d, f)
            sc = eikon.Scene.load(path)
            t = eikon.trace_polarised(sc, [0.3, 0.2, -20], [0, 0, 1], 589.2938, stokes=[1, 1, 0, 0],
                                      device="cpu")
            s = t["stokes_out"]
            self.assertLessEqual(s[3] / s[0], -0.999)  # left circular (quartz: slow axis at +45°)
            self.assertEqual(t["beams"][0]["branches"], 2)
            out = subprocess.run([EIKON, "trace", path, "--origin", "0.3,0.2,-20", "--dir", "0,0,1",
                                  "--wavelength", "589.2938", "--stokes", "1,1,0,0", "--json",
                                  "--reference", "-q"], capture_output=True, text=True, check=True)
            cli = np.array(json.loads(out.stdout)["stokes_out"])
            np.testing.assert_allclose(cli, s, atol=1e-12)

    def test_bad_input_raises_value_error(self):
        sc = eikon.Scene.parse(scene_dict([ASIDE]))
        for kw in [{"stokes": [1, 0, 0]}, {"stokes": [0, 0, 0, 0]}, {"stokes": [1, 1, 1, 0]},
                   {"device": "tpu"}]:
            with self.assertRaises(ValueError, msg=str(kw)):
                eikon.trace_polarised(sc, [0, 0, -20], [0, 0, 1], 550.0, **kw)

    def test_more_sheets_than_the_gpu_takes_name_the_ninth(self):
        # The GPU twin takes at most 8 polariser sheets; the 9th (/objects/9 after the sphere) is
        # named with the remedy, and the CPU twin traces the scene.
        sc = eikon.Scene.parse(scene_dict([ASIDE] + [sheet(-8, 0)] * 9), "nine.json")
        with self.assertRaises(RuntimeError) as e:
            eikon.trace_polarised(sc, [0, 0, -20], [0, 0, 1], 550.0, device="gpu")
        msg = str(e.exception)
        self.assertTrue(msg.startswith("nine.json: /objects/9: "), msg)
        self.assertIn("at most 8 polariser sheets; this is sheet 9 of 9", msg)
        self.assertIn('device="cpu"', msg)
        t = eikon.trace_polarised(sc, [0, 0, -20], [0, 0, 1], 550.0, device="cpu")
        self.assertAlmostEqual(t["stokes_out"][0], 0.5, delta=1e-9)  # one axis: Malus at 0°


if __name__ == "__main__":
    unittest.main()
