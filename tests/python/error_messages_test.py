"""Every exception the eikon module raises shows its message as the eikon command shows it: control
characters, a NUL and bytes that are not UTF-8 in the input quoted (a file name, a material name,
a CSV's text, a JSON string) appear escaped (\\x1b, \\x0a), never raw. Raw, an ESC recoloured the
terminal that printed the message and a newline forged a second line of it.
Run by CTest (python.error_messages) with EIKON_PYTHON_DIR.
"""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402

NASTY = "a\x1b[31mred\nforged line\x07\x7f"


def raw_controls(text):
    """The control characters (C0, DEL, C1) found raw in `text`."""
    return [c for c in text if ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0]


class ErrorMessages(unittest.TestCase):
    def message_of(self, call, error):
        with self.assertRaises(error) as cm:
            call()
        return str(cm.exception)

    def assert_escaped(self, message):
        self.assertEqual(raw_controls(message), [], repr(message))
        self.assertIn("\\x1b[31mred\\x0aforged line\\x07\\x7f", message)

    def test_a_material_name_is_escaped(self):
        m = self.message_of(lambda: eikon.load_material(NASTY), ValueError)
        self.assert_escaped(m)
        self.assertTrue(m.startswith("no material 'a\\x1b"), m)

    def test_a_scene_path_is_escaped(self):
        m = self.message_of(lambda: eikon.Scene.load("/nonexistent/" + NASTY + ".json"),
                            RuntimeError)
        self.assert_escaped(m)

    def test_a_data_file_name_and_its_text_are_escaped(self):
        m = self.message_of(lambda: eikon.read_index_data("/nonexistent/" + NASTY + ".csv"),
                            Exception)
        self.assert_escaped(m)
        m = self.message_of(
            lambda: eikon.parse_index_csv("wavelength_nm,n\n500,1.5\n600," + NASTY + "\n", NASTY),
            ValueError)
        self.assertEqual(raw_controls(m), [], repr(m))
        self.assertTrue(m.startswith("a\\x1b[31mred\\x0aforged line"), m)

    def test_a_json_string_in_a_scene_is_escaped(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "s.json")
            with open(path, "w") as f:
                f.write('{"materials": {"g": {"n": 1.5}}, "objects": [{"shape": "sphere", '
                        '"radius": 1, "material": "a\\u001b[31mred\\nforged line\\u0007\\u007f"}]}')
            m = self.message_of(lambda: eikon.Scene.load(path), RuntimeError)
            self.assert_escaped(m)

    def test_python_errors_raised_in_callbacks_pass_unchanged(self):
        def field(p):
            raise KeyError("own\nerror")
        f = eikon.AnalyticField.from_function(field, [-1, -1, -1], [1, 1, 1], 0.5)
        with self.assertRaises(KeyError) as cm:
            f.trace([0, 0, -0.9], [0, 0, 1])
        self.assertEqual(cm.exception.args, ("own\nerror",))


if __name__ == "__main__":
    unittest.main()
