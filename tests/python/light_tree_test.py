"""eikon.light_tree / Renderer.light_tree (`eikon trace --tree`, docs/design.md §3): the light tree
of one ray on the CPU twin, as the CLI's JSON.

  - a non-absorbing slab (n = 1.5) at normal incidence: the exit leaves on the incident side sum to
    the total reflectance 2R/(1 + R), R = 0.04, within the weight cut below min_weight (1e-13 here,
    so within 1e-11), and exit + absorbed + cut = 1 to 1e-12;
  - `eikon trace --tree` prints the same tree (node for node, weights to 1e-15);
  - min_weight or max_depth out of range raise ValueError naming the keyword.
Run by CTest (python.light_tree) with EIKON_BINARY and EIKON_PYTHON_DIR.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import eikon  # noqa: E402

EIKON = os.environ["EIKON_BINARY"]

SCENE = {"environment": {"type": "constant", "radiance": 1}, "interfaces": "sharp",
         "volume": {"bounds_min": [-5, -5, -5], "bounds_max": [5, 5, 5], "resolution": 32},
         "materials": {"glass": {"n": 1.5}},
         "objects": [{"shape": "box", "center": [0, 0, 0], "size": [6, 6, 4],
                      "material": "glass"}]}


class LightTree(unittest.TestCase):
    def test_slab_total_reflectance(self):
        r = eikon.Renderer(eikon.Scene.parse(SCENE))
        j = r.light_tree([0.3, 0.2, -20], [0, 0, 1], min_weight=1e-13)
        self.assertEqual(len(j["trees"]), 1)
        t = j["trees"][0]
        self.assertEqual(t["mode"], "isotropic")
        tot = t["totals"]
        self.assertAlmostEqual(tot["exit"] + tot["absorbed"] + tot["stopped"] + tot["cut"], 1.0,
                               delta=1e-12)
        front = sum(n["weight"] for n in t["nodes"]
                    if n["event"] == "exit" and n["direction"][2] < 0)
        self.assertLess(tot["cut"], 1e-11)
        self.assertAlmostEqual(front, 2 * 0.04 / 1.04, delta=tot["cut"] + 1e-12)

    def test_the_cli_prints_the_same_tree(self):
        j = eikon.light_tree(eikon.Scene.parse(SCENE), [0.3, 0.2, -20], [0, 0, 1], max_depth=5)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "slab.json")
            with open(path, "w") as f:
                json.dump(SCENE, f)
            out = subprocess.run([EIKON, "trace", path, "--origin", "0.3,0.2,-20", "--dir",
                                  "0,0,1", "--tree", "--tree-max-depth", "5", "-q"],
                                 capture_output=True, text=True, check=True).stdout
        cli = json.loads(out)
        a, b = j["trees"][0]["nodes"], cli["trees"][0]["nodes"]
        self.assertEqual(len(a), len(b))
        for p, q in zip(a, b):
            self.assertEqual((p["id"], p["parent"], p["event"]), (q["id"], q["parent"], q["event"]))
            self.assertAlmostEqual(p["weight"], q["weight"], delta=1e-15)

    def test_bad_limits_raise(self):
        r = eikon.Renderer(eikon.Scene.parse(SCENE))
        for kw, word in [({"min_weight": 0.0}, "min_weight must be in [1e-15, 1]"),
                         ({"min_weight": 2.0}, "min_weight must be in [1e-15, 1]"),
                         ({"max_depth": 0}, "max_depth must be in [1, 1024]")]:
            with self.assertRaises(ValueError) as e:
                r.light_tree([0, 0, -20], [0, 0, 1], **kw)
            self.assertIn(word, str(e.exception))


if __name__ == "__main__":
    unittest.main()
