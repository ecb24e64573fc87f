"""Python's optics helpers, dispersion models and analytic fields refuse degenerate input with a
ValueError naming the argument, instead of returning NaN or nonsense.

The rules are the rest of eikon's: refractive indices in [1, 10] (core/scene/limits.h, as a
scene's), directions finite and non-zero, positions within +-1e12 mm, wavelengths of a dispersion
model in [100, 100000] nm (the wavelengths `eikon fit` takes). Before, critical_angle(1, 1.5) and
refract_isotropic(n2=0) returned NaN, Uniaxial(1.5, 1e300) was accepted, Dispersion.constant(-1)
and calcite.uniaxial_at(-5 nm) gave indices, cauchy_approximation across a Sellmeier pole gave
coefficients of ~1e15, and AnalyticField took a cell of 0 or NaN, swapped bounds, a negative n0 or
a from_function returning n = 0, then traced NaN exit points and negative optical paths.
Run by CTest (python.optics_arguments) with EIKON_PYTHON_DIR.
"""
import math
import os
import sys
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

NAN = float("nan")
BOX = ([-5, -5, -5], [5, 5, 5])


class Refused(unittest.TestCase):
    def refused(self, call, message, error=ValueError):
        """`call` raises `error` whose message starts with `message`."""
        with self.assertRaises(error) as cm:
            call()
        self.assertTrue(str(cm.exception).startswith(message),
                        f"{str(cm.exception)!r} does not start with {message!r}")


class Optics(Refused):
    def test_critical_angle_needs_the_denser_medium_first(self):
        self.refused(lambda: eikon.critical_angle(1, 1.5),
                     "no critical angle for n1 = 1 <= n2 = 1.5: total internal reflection needs "
                     "the denser medium first (n1 > n2)")
        self.refused(lambda: eikon.critical_angle(1.5, 1.5), "no critical angle for n1 = 1.5")
        self.refused(lambda: eikon.critical_angle(NAN, 1), "n1 must be a refractive index in [1, 10]")
        self.assertAlmostEqual(eikon.critical_angle(1.5, 1), math.asin(1 / 1.5), places=15)

    def test_indices_are_refractive_indices(self):
        self.refused(lambda: eikon.refract_isotropic([0, 0, 1], [0, 0, -1], 1, 0),
                     "n2 must be a refractive index in [1, 10], got 0")
        self.refused(lambda: eikon.Uniaxial(1.5, 1e300),
                     "n_e must be a refractive index in [1, 10], got 1e+300")
        self.refused(lambda: eikon.Uniaxial(0.5, 1.5), "n_o must be a refractive index in [1, 10]")
        self.refused(lambda: eikon.brewster_angle(1, -2), "n2 must be a refractive index")
        self.refused(lambda: eikon.fresnel_reflectance(0.5, 1, 11), "n2 must be a refractive index")
        self.refused(lambda: eikon.pleochroism_weights([0.1], 1.6, NAN),
                     "n_e must be a refractive index")
        crystal = eikon.Uniaxial(1.658, 1.486)
        self.refused(lambda: eikon.refract_into_uniaxial([0, 0, 1], [0, 0, 1], 0.5, crystal),
                     "n1 must be a refractive index")
        self.refused(lambda: eikon.uniaxial_exit(crystal, "e", [0, 0, 1], [0, 0, 1], 20),
                     "n2 must be a refractive index")

    def test_directions_are_finite_and_non_zero(self):
        self.refused(lambda: eikon.refract_isotropic([0, 0, 0], [0, 0, -1], 1, 1.5),
                     "s_in must be a non-zero vector")
        self.refused(lambda: eikon.refract_isotropic([0, 0, 1], [0, NAN, -1], 1, 1.5),
                     "normal must be three finite numbers, got nan on y")
        crystal = eikon.Uniaxial(1.658, 1.486)
        self.refused(lambda: crystal.index("e", [0, 0, 0]), "s must be a non-zero vector")
        self.refused(lambda: crystal.ray_direction("e", [1e308, 1e308, 0]),
                     "s must have a finite length")
        self.refused(lambda: crystal.walk_off_angle([0, 0]), "s must be three numbers")
        self.refused(lambda: eikon.Uniaxial(1.6, 1.5, [0, 0, 0]), "axis must be a non-zero vector")
        self.refused(lambda: eikon.BMMapping(crystal).refract_e([0, 0, 0], [0, 0, 1]),
                     "p_in must be a non-zero vector")
        self.refused(lambda: crystal.extraordinary_index_at([0.1, NAN]),
                     "theta must be a finite angle (rad), got nan")
        self.refused(lambda: eikon.fresnel_reflectance(5, 1, 1.5), "cos_i must be in [-1, 1], got 5")
        # What is fine stays fine: any non-zero length, any finite angle, cos_i rounded past 1.
        self.assertAlmostEqual(crystal.index("e", [0, 0, 7]), 1.658, places=12)
        self.assertEqual(eikon.fresnel_reflectance(1 + 1e-12, 1, 1.5)[2],
                         eikon.fresnel_reflectance(1, 1, 1.5)[2])
        self.assertEqual(crystal.extraordinary_index_at([0.0, 10.0]).shape, (2,))


class Dispersion(Refused):
    def test_indices_and_wavelengths(self):
        self.refused(lambda: eikon.Dispersion.constant(-1),
                     "n must be a refractive index in [1, 10], got -1")
        calcite = eikon.load_material("calcite")
        self.refused(lambda: calcite.uniaxial_at(-5), "lambda_nm must be in [100, 100000] nm, got -5")
        self.refused(lambda: calcite.uniaxial_at(589, axis=[0, 0, 0]), "axis must be a non-zero vector")
        self.refused(lambda: calcite.n_o.index([500, 1e6]), "lambda_nm must be in [100, 100000] nm")
        self.refused(lambda: calcite.n_o.derivative(NAN), "lambda_nm must be in [100, 100000] nm")
        c = calcite.uniaxial_at(eikon.FRAUNHOFER["D"])
        self.assertAlmostEqual(c.n_o, 1.658, places=3)
        # A material whose index leaves [1, 10] at the wavelength is named.
        pole = eikon.Dispersion.sellmeier([1.0], [0.3481])  # a pole at 590 nm
        self.assertTrue(math.isnan(float(pole.index(580.0))))  # documented: no real index there
        self.refused(lambda: pole.cauchy_approximation(400, 800),
                     "the Sellmeier term 1 has a pole at 590 nm (C1 = 0.3481 um^2), inside "
                     "[400, 800] nm")
        self.refused(lambda: pole.cauchy_approximation(100, 200),
                     "the model gives n = 0.98510047801704")
        bk7 = eikon.load_material("N-BK7").n
        self.refused(lambda: bk7.cauchy_approximation(780, 380), "lo_nm must be below hi_nm")
        self.refused(lambda: bk7.cauchy_approximation(10, 780), "lo_nm must be in [100, 100000] nm")
        self.assertLess(bk7.cauchy_approximation(380, 780)["max_error"], 1e-3)


class AnalyticField(Refused):
    def linear(self, *box, n0=1.5, gradient=(0, 0.01, 0)):
        return eikon.AnalyticField.linear(n0, list(gradient), [0, 0, 0], *box)

    def test_box_and_cell(self):
        for cell in (0, -1, NAN, math.inf):
            self.refused(lambda: self.linear(*BOX, cell), "cell must be a finite number > 0, got ")
        self.refused(lambda: self.linear([5, -5, -5], [-5, 5, 5], 0.5),
                     "bounds_min must be below bounds_max on every axis, got 5 >= -5 on x")
        self.refused(lambda: self.linear([-5, -5, -5], [5, 5, -5], 0.5),
                     "bounds_min must be below bounds_max on every axis, got -5 >= -5 on z")
        self.refused(lambda: self.linear([NAN, -5, -5], [5, 5, 5], 0.5),
                     "bounds_min must be three finite numbers, got nan on x")
        self.refused(lambda: self.linear([-5, -5, -5], [5, 5, 1e13], 0.5),
                     "bounds_max must be within ±1e12 mm on each axis")

    def test_profiles(self):
        self.refused(lambda: self.linear(*BOX, 0.5, gradient=(0, NAN, 0)),
                     "gradient must be three finite numbers, got nan on y")
        self.refused(lambda: self.linear(*BOX, 0.5, n0=-1.5),
                     "n0 must be a refractive index in [1, 10], got -1.5")
        self.refused(lambda: self.linear(*BOX, 0.5, gradient=(0, 0.2, 0)),
                     "the linear field n0 + gradient·(x − origin) gives n = 0.5 at (-5, -5, -5): "
                     "indices must be in [1, 10]")
        self.refused(lambda: eikon.AnalyticField.maxwell_fisheye(2, 0, [0, 0, 0], *BOX, 0.5),
                     "radius must be a finite number > 0, got 0")
        self.refused(lambda: eikon.AnalyticField.maxwell_fisheye(2, 1, [0, 0, 0], *BOX, 0.5),
                     "the Maxwell fish-eye n0/(1 + r²/R²) gives n = 0.02631578947368421 at (-5, -5, -5)")
        self.refused(lambda: eikon.AnalyticField.maxwell_fisheye(-2, 10, [0, 0, 0], *BOX, 0.5),
                     "n0 must be a refractive index")
        self.refused(lambda: eikon.AnalyticField.luneburg(NAN, [0, 0, 0], *BOX, 0.5),
                     "radius must be a finite number > 0, got nan")
        self.refused(lambda: eikon.AnalyticField.luneburg(4, [0, NAN, 0], *BOX, 0.5),
                     "center must be three finite numbers")
        # In range, every profile traces to finite numbers.
        for f in (self.linear(*BOX, 0.5),
                  eikon.AnalyticField.maxwell_fisheye(2, 10, [0, 0, 0], *BOX, 0.5),
                  eikon.AnalyticField.luneburg(4, [0, 0, 0], *BOX, 0.5)):
            t = f.trace([0, 1, -4.5], [0, 0, 1])
            self.assertTrue(np.isfinite(t["exit_point"]).all() and t["optical_path_mm"] > 0, t)

    def test_from_function_values_are_checked_where_sampled(self):
        def field(n, grad):
            return eikon.AnalyticField.from_function(lambda p: (n, grad), *BOX, 0.5)

        self.refused(lambda: field(0.0, [0, 0, 0]).trace([0, 0, -4], [0, 0, 1]),
                     "fn gives n = 0 at (0, 0, -4): indices must be in [1, 10]")
        self.refused(lambda: field(NAN, [0, 0, 0]).trace([0, 0, -4], [0, 0, 1]), "fn gives n = nan")
        self.refused(lambda: field(1.5, [0, NAN, 0]).trace([0, 0, -4], [0, 0, 1]),
                     "fn's gradient at (0, 0, -4) must be three finite numbers, got nan on y")
        self.refused(lambda: eikon.AnalyticField.from_function(lambda p: 1.5, *BOX, 0.5)
                     .trace([0, 0, -4], [0, 0, 1]), "fn must return (n, gradient), got 1.5",
                     TypeError)
        t = field(1.5, [0, 0, 0]).trace([0, 0, -4], [0, 0, 1])
        np.testing.assert_allclose(t["exit_point"], [0, 0, 5])
        self.assertAlmostEqual(t["optical_path_mm"], 1.5 * 9, places=9)

    def test_trace_arguments_are_renderer_traces(self):
        f = self.linear(*BOX, 0.5)
        self.refused(lambda: f.trace([0, 0, -4], [0, 0, 0]), "direction must be a non-zero vector")
        self.refused(lambda: f.trace([0, 0, NAN], [0, 0, 1]), "origin must be within ±1e12 mm")
        self.refused(lambda: f.trace([0, 0, -4], [0, 0, 1], eikon.MarchSettings(step_voxels=0)),
                     "march.step_voxels must be in (0, 4] voxels")


if __name__ == "__main__":
    unittest.main(verbosity=2)
