"""eikon.fit_dispersion takes its data by the rules of `eikon fit`'s data files, with the same words.

Both run fitting/index_data.h's checks (checkIndexSeries for arrays, the readers for files): every
value finite, wavelengths in [100, 100000] nm, n in [1, 10] (what a scene takes), sigma finite and
> 0, no repeated wavelength, at least two points; points out of wavelength order are sorted with a
warning (the CLI prints "eikon: warning: ...", Python issues a UserWarning). A bad point is named
by its index in Python ("point 0: n must be >= 1, got 0.53") where the CLI names the file and line
("a.csv:2: n must be >= 1, got 0.53"). Before, unsorted wavelengths failed with an unrelated
message, sigma <= 0 and n < 1 were fitted or reported as a "rank-deficient start", and
max_iterations=-1 surfaced Ceres' own option text. Run by CTest (python.fit_dispersion) with
EIKON_BINARY and EIKON_PYTHON_DIR.
"""
import os
import subprocess
import sys
import tempfile
import unittest
import warnings

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]
W = [400.0, 500.0, 600.0, 700.0, 800.0]
N = [1.53, 1.52, 1.515, 1.512, 1.51]


class FitDispersion(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.tmp.cleanup()

    def cli(self, lam, n, sigma=None):
        """`eikon fit` of the same points as a CSV: (exit code, stderr lines)."""
        path = os.path.join(self.tmp.name, "data.csv")
        with open(path, "w") as f:
            f.write("wavelength_nm,n" + (",sigma" if sigma is not None else "") + "\n")
            for k in range(len(lam)):
                f.write(f"{lam[k]!r},{n[k]!r}" + (f",{sigma[k]!r}" if sigma is not None else "") + "\n")
        r = subprocess.run([EIKON, "fit", path, "-o", os.path.join(self.tmp.name, "m.json")],
                           capture_output=True, text=True, timeout=120)
        return r.returncode, r.stderr.strip().splitlines()

    def python_error(self, lam, n, sigma=None, **kw):
        with self.assertRaises(ValueError) as cm:
            eikon.fit_dispersion(lam, n, sigma=sigma, **kw)
        return str(cm.exception)

    def test_bad_points_are_refused_as_the_cli_refuses_them(self):
        cases = [
            (W, [0.53] + N[1:], None, 0, "n must be >= 1, got 0.53"),
            (W, N[:3] + [10.5] + N[4:], None, 3, "n must be <= 10, got 10.5 (a scene takes indices "
             "in [1, 10])"),
            (W, N, [1e-4, 1e-4, 0.0, 1e-4, 1e-4], 2, "sigma of n must be a finite number > 0"),
            (W, N, [-1.0] * 5, 0, "sigma of n must be a finite number > 0"),
            ([50.0] + W[1:], N, None, 0, "wavelength 50 nm is outside [100, 100000] nm, the "
             "wavelengths a fit takes"),
            (W, N[:1] + [float("nan")] + N[2:], None, 1, "n is not a finite number"),
        ]
        for lam, n, sigma, point, complaint in cases:
            with self.subTest(complaint=complaint):
                message = self.python_error(lam, n, sigma)
                self.assertEqual(message, f"point {point}: {complaint}")
                code, lines = self.cli(lam, n, sigma)
                self.assertNotEqual(code, 0)
                self.assertEqual(len(lines), 1, lines)
                # The CLI names the file's line (the header is line 1) and, for a wavelength the
                # fit does not take, adds how to leave rows out.
                self.assertIn(f"data.csv:{point + 2}: {complaint}", lines[0])

    def test_repeated_wavelengths_and_too_few_points(self):
        self.assertEqual(self.python_error([400.0, 500, 500, 700, 800], N),
                         "point 2: duplicate wavelength 500 nm (also at point 1)")
        self.assertEqual(self.python_error([500.0], [1.5]),
                         "lambda_nm: only one data point (point 0); a dispersion fit needs at least 2")
        self.assertEqual(self.python_error(W, N[:4]),
                         "lambda_nm: 5 wavelengths, 4 indices: each point needs one of each")
        self.assertEqual(self.python_error(W, N, sigma=[1e-4] * 4),
                         "lambda_nm: 5 wavelengths, 5 indices and 4 sigmas: each point needs one "
                         "of each")
        self.assertEqual(self.python_error(np.ones((5, 1)), N),
                         "lambda_nm must be a 1-D sequence of numbers")

    def test_unsorted_points_are_sorted_with_a_warning(self):
        order = [4, 0, 2, 1, 3]
        lam, n = [W[k] for k in order], [N[k] for k in order]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fit = eikon.fit_dispersion(lam, n)
        self.assertEqual([str(w.message) for w in caught],
                         ["lambda_nm: n points are not in ascending wavelength order; sorted them"])
        self.assertEqual(caught[0].category, UserWarning)
        np.testing.assert_allclose(fit.coeffs, eikon.fit_dispersion(W, N).coeffs, rtol=1e-12)
        self.assertEqual(fit.range_nm, (400.0, 800.0))
        code, lines = self.cli(lam, n)
        self.assertEqual(code, 0)
        self.assertIn("n rows are not in ascending wavelength order; sorted them", lines[0])
        with warnings.catch_warnings():  # warnings as errors: Python's --strict
            warnings.simplefilter("error")
            with self.assertRaises(UserWarning):
                eikon.fit_dispersion(lam, n)

    def test_max_iterations(self):
        for bad in (-1, 0, 100001):
            self.assertEqual(self.python_error(W, N, max_iterations=bad),
                             f"max_iterations must be in [1, 100000], got {bad}")
        self.assertEqual(eikon.fit_dispersion(W, N, max_iterations=1).points, 5)


if __name__ == "__main__":
    unittest.main(verbosity=2)
