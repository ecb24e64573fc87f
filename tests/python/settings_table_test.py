"""One table of settings (core/session/settings.h) makes the CLI's options and Python's keywords.

Every setting of the table that a front end takes is there, under its name, with the table's
default and help: `eikon render --help` (and `eikon trace --help`, `eikon view --help`) lists
"--NAME" with the table's help line, and Renderer.render, Renderer.simulate_light and
Renderer.trace have the keyword with the table's default (a "march.X" keyword is an attribute of
eikon.MarchSettings). A setting added to the table that a front end does not make fails here.
Run by CTest (python.settings_table) with EIKON_BINARY and EIKON_PYTHON_DIR.
"""
import os
import re
import subprocess
import sys
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]

PYTHON_FRONTS = {
    "Renderer.render": eikon.Renderer.render,
    "Renderer.simulate_light": eikon.Renderer.simulate_light,
    "Renderer.trace": eikon.Renderer.trace,
}


def words(text):
    """Text with every run of blanks as one space (the help is wrapped by CLI11)."""
    return " ".join(text.split())


def python_default(kind, value):
    """The repr pybind11 shows for a keyword's default in the signature."""
    if kind == "flag":
        return repr(value == "true")
    if kind in ("choice", "text"):
        return repr(value)
    if value == "":
        return "None"
    return repr(int(value)) if kind == "integer" else repr(float(value))


class SettingsTable(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.table = eikon.settings()
        cls.help = {}
        for command in ("render", "trace", "view"):
            r = subprocess.run([EIKON, command, "--help"], capture_output=True, text=True,
                               timeout=60)
            assert r.returncode == 0, r.stderr
            cls.help[command] = words(r.stdout)

    def test_the_table_is_not_empty(self):
        names = [s["name"] for s in self.table]
        for name in ("width", "spp", "wavelengths", "step", "light-splat", "threads", "device"):
            self.assertIn(name, names)

    def test_every_cli_setting_is_an_option_with_the_tables_help(self):
        count = 0
        for s in self.table:
            for command in ("render", "trace", "view"):
                if command not in s["help"]:
                    continue
                with self.subTest(setting=s["name"], command=command):
                    text = self.help[command]
                    self.assertRegex(text, r"--" + re.escape(s["name"]) + r"\b")
                    self.assertIn(words(s["help"][command]), text)
                    count += 1
        self.assertGreaterEqual(count, 20)

    def test_every_python_setting_is_a_keyword_with_the_tables_default(self):
        march = eikon.MarchSettings()
        count = 0
        for s in self.table:
            for front, function in PYTHON_FRONTS.items():
                if front not in s["help"]:
                    continue
                keyword = s["keyword"]
                with self.subTest(setting=s["name"], front=front, keyword=keyword):
                    if keyword.startswith("march."):
                        self.assertTrue(hasattr(march, keyword[len("march."):]))
                        continue
                    signature = function.__doc__.splitlines()[0]
                    m = re.search(r"[(, ]" + re.escape(keyword) + r": [^=]*?= ", signature)
                    self.assertIsNotNone(m, signature)
                    expected = python_default(s["kind"], s["defaults"][front])
                    self.assertTrue(signature[m.end():].startswith(expected),
                                    f"{keyword}: expected default {expected} in {signature}")
                    self.assertIn(words(s["help"][front]), words(function.__doc__))
                    count += 1
        self.assertGreaterEqual(count, 20)

    def test_python_refuses_with_the_tables_words(self):
        # The same range, the same words, under the Python keyword.
        r = eikon.Renderer(eikon.Scene.load(os.path.join(os.path.dirname(__file__), "..", "..",
                                                         "scenes", "glass_sphere.json")))
        with self.assertRaises(ValueError) as cm:
            r.simulate_light(max_patches=10)
        self.assertEqual(str(cm.exception), "max_patches must be in [1024, 16777216]")
        with self.assertRaises(ValueError) as cm:
            r.simulate_light(split_voxels=9)
        self.assertEqual(str(cm.exception), "split_voxels must be in [0.25, 8] voxels")
        with self.assertRaises(ValueError) as cm:
            r.simulate_light(reflections=65)
        self.assertEqual(str(cm.exception), "reflections must be in [0, 64]")
        self.assertEqual(eikon.voxelize_count(), 0)


if __name__ == "__main__":
    unittest.main()
