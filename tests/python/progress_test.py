"""Progress of the module's long calls on stderr (python/progress.h).

  - render(progress=True) shows each stage on stderr (a tqdm bar when tqdm is installed, else plain
    "eikon: rendering 100.0%" lines), voxelising, the light and the render of a lit scene included;
  - progress=False, and $EIKON_PROGRESS=never with the default progress=None, print nothing;
  - without tqdm (its import made to fail) the same stages come as plain lines, no carriage
    returns;
  - a bad $EIKON_PROGRESS is a ValueError naming it, a bad progress= a TypeError, before any work.
Each case runs in a subprocess so that its stderr is the module's alone.
Run by CTest (python.progress) with EIKON_PYTHON_DIR.
"""
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

# A glass ball over a diffuse floor under a directional light: a render voxelises, simulates the
# light and renders (three stages).
LIT = {
    "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 16, "height": 12},
    "environment": {"type": "constant", "radiance": 0.1},
    "volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": 16},
    "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
    "objects": [{"shape": "sphere", "center": [0, 2, 0], "radius": 5, "material": "glass"},
                {"shape": "box", "center": [0, -10, 0], "size": [24, 2, 24], "material": "floor"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1.0}],
}


def run(body, env=None, no_tqdm=False):
    """Run `body` (with `scene` loaded) in a fresh python; returns (code, stderr)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "lit.json")
        with open(path, "w") as f:
            json.dump(LIT, f)
        prologue = "import sys\n"
        if no_tqdm:
            prologue += "sys.modules['tqdm'] = None  # import tqdm raises ImportError\n"
        prologue += textwrap.dedent(f"""
            sys.path.insert(0, {os.environ['EIKON_PYTHON_DIR']!r})
            import eikon
            scene = eikon.Scene.load({path!r})
            """)
        e = dict(os.environ)
        e.pop("EIKON_PROGRESS", None)
        e.update(env or {})
        r = subprocess.run([sys.executable, "-c", prologue + textwrap.dedent(body)],
                           capture_output=True, text=True, env=e, cwd=tmp, timeout=300)
        return r.returncode, r.stderr


def has_tqdm():
    return subprocess.run([sys.executable, "-c", "import tqdm"], capture_output=True).returncode == 0


class Progress(unittest.TestCase):
    def test_render_shows_its_stages(self):
        code, err = run("eikon.render(scene, device='cpu', light_cache=False, progress=True)")
        self.assertEqual(code, 0, err)
        for stage in ("eikon: voxelising", "eikon: light 1 light", "eikon: rendering"):
            self.assertIn(stage, err)
        self.assertIn("100", err)

    @unittest.skipUnless(has_tqdm(), "tqdm is not installed (python3-tqdm)")
    def test_tqdm_draws_bars(self):
        code, err = run("eikon.render(scene, device='cpu', light_cache=False, progress=True)")
        self.assertEqual(code, 0, err)
        # Each stage's bar, "{desc} {percentage}%|{bar}| {elapsed}<{remaining}", ends full.
        for stage in ("eikon: voxelising 100.0%|", "eikon: rendering 100.0%|"):
            self.assertIn(stage, err)

    def test_plain_lines_without_tqdm(self):
        code, err = run("eikon.render(scene, device='cpu', light_cache=False, progress=True)",
                        no_tqdm=True)
        self.assertEqual(code, 0, err)
        self.assertNotIn("\r", err)
        lines = err.splitlines()
        self.assertTrue(lines, err)
        for line in lines:
            self.assertTrue(line.startswith("eikon: "), line)
        self.assertIn("eikon: rendering 100.0%", err)

    def test_off(self):
        code, err = run("eikon.render(scene, device='cpu', light_cache=False, progress=False)",
                        env={"EIKON_PROGRESS": "always"})
        self.assertEqual(code, 0, err)
        self.assertEqual(err, "")
        code, err = run("eikon.render(scene, device='cpu', light_cache=False)",
                        env={"EIKON_PROGRESS": "never"})
        self.assertEqual(code, 0, err)
        self.assertEqual(err, "")
        # The environment's always shows a short call's stages, as progress=True does.
        code, err = run("eikon.render(scene, device='cpu', light_cache=False)",
                        env={"EIKON_PROGRESS": "always"}, no_tqdm=True)
        self.assertEqual(code, 0, err)
        self.assertIn("eikon: rendering 100.0%", err)

    def test_bad_words(self):
        code, err = run("""
            try:
                eikon.render(scene, device='cpu', light_cache=False)
            except ValueError as e:
                print(e, file=sys.stderr)
            try:
                eikon.render(scene, device='cpu', light_cache=False, progress='yes')
            except TypeError as e:
                print(e, file=sys.stderr)
            print(eikon.voxelize_count(), file=sys.stderr)
            """, env={"EIKON_PROGRESS": "loud"})
        self.assertEqual(code, 0, err)
        self.assertIn("EIKON_PROGRESS must be auto, always or never", err)
        self.assertIn("progress must be True, False or None, got str", err)
        self.assertTrue(err.rstrip().endswith("0"), err)  # nothing voxelised


if __name__ == "__main__":
    unittest.main()
