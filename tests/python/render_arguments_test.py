"""Renderer arguments that used to be taken as they came: light_cache of any type, trace_rays of any
size, trace_polarised's source angle.

  - render(light_cache=...) takes True, False, None or a folder (str or os.PathLike); light_cache=5
    made a folder named "5" in the working directory, light_cache=[1] one named "[1]".
  - trace_rays refuses, with the numbers and before copying its inputs, a batch whose memory the
    host cannot hold (1e8 rays under a 6 GB limit raised a bare "std::bad_alloc", 1e9 rays of a
    broadcast view were copied until the kernel killed the process); the GPU twin traces a batch
    larger than one storage buffer holds in several dispatches (on lavapipe, 128 MiB: more than
    2^20 rays failed with "buffer 'trace results' needs 134 MiB").
  - trace_polarised's source_angle_rad (the angular size of a light sample) is in (0, pi]; 100 rad
    merged every beam silently.
Run by CTest (python.render_arguments) with EIKON_PYTHON_DIR.
"""
import os
import pathlib
import subprocess
import sys
import tempfile
import textwrap
import unittest

sys.path.insert(0, os.environ["EIKON_PYTHON_DIR"])
import numpy as np  # noqa: E402

import eikon  # noqa: E402

# A glass ball over a diffuse floor under a directional light: render() simulates the light
# through the light cache first.
LIT = {
    "camera": {"position": [0, 0, -60], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 8, "height": 6},
    "environment": {"type": "constant", "radiance": 0.1},
    "volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": 16},
    "materials": {"glass": {"n": 1.5168}, "floor": {"n": 1, "opacity": 1, "albedo": 0.8}},
    "objects": [{"shape": "sphere", "center": [0, 2, 0], "radius": 5, "material": "glass"},
                {"shape": "box", "center": [0, -10, 0], "size": [24, 2, 24], "material": "floor"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1.0}],
}

SPHERE = {
    "camera": {"position": [0, 0, -40], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 30,
               "width": 8, "height": 6},
    "volume": {"bounds_min": [-8, -8, -8], "bounds_max": [8, 8, 8], "resolution": 16},
    "materials": {"glass": {"n": 1.5}},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 4, "material": "glass"}],
}


class LightCache(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.cwd = os.getcwd()
        os.chdir(self.tmp.name)  # where a folder named after a bad value used to appear

    def tearDown(self):
        os.chdir(self.cwd)
        self.tmp.cleanup()

    def test_a_value_that_is_not_a_folder_is_a_type_error(self):
        r = eikon.Renderer(eikon.Scene.parse(LIT))
        before = eikon.voxelize_count()
        for bad, name in ((5, "int"), ([1], "list"), (2.5, "float"), (b"cache", "bytes")):
            with self.assertRaises(TypeError) as cm:
                r.render(light_cache=bad)
            self.assertEqual(str(cm.exception), "light_cache must be True, False, None or a folder "
                             "(str or os.PathLike), got " + name)
            with self.assertRaises(TypeError):  # checked whether or not the light is simulated
                r.render(light=False, light_cache=bad)
        with self.assertRaises(ValueError) as cm:
            r.render(light_cache="")
        self.assertIn("light_cache must name a folder", str(cm.exception))
        self.assertEqual(os.listdir("."), [])
        self.assertEqual(eikon.voxelize_count(), before)  # refused before voxelising

    def test_a_path_like_folder_holds_the_light(self):
        folder = pathlib.Path(self.tmp.name) / "lightcache"
        img = eikon.Renderer(eikon.Scene.parse(LIT)).render(light_cache=folder)
        self.assertEqual(img.shape, (6, 8, 3))
        self.assertTrue(any(f.startswith("light-") for f in os.listdir(folder)), os.listdir(folder))
        self.assertEqual(os.listdir("."), ["lightcache"])
        for off in (False, None):
            self.assertEqual(eikon.Renderer(eikon.Scene.parse(LIT)).render(light_cache=off).shape,
                             (6, 8, 3))


class TraceRaysSize(unittest.TestCase):
    def child(self, rays):
        """trace_rays of `rays` broadcast rays in a child whose address space is capped 2 GiB above
        what it uses: refused with the numbers, never a MemoryError or the OOM killer."""
        code = textwrap.dedent(f"""
            import resource, sys
            sys.path.insert(0, {os.environ['EIKON_PYTHON_DIR']!r})
            import numpy as np, eikon
            r = eikon.Renderer(eikon.Scene.parse({SPHERE!r}))
            used = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
            cap = used + (2 << 30)
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
            n = {rays}
            try:
                r.trace_rays(np.broadcast_to(np.array([0, 0, -20.]), (n, 3)),
                             np.broadcast_to(np.array([0, 0, 1.]), (n, 3)))
                print("traced")
            except Exception as e:
                print(type(e).__name__ + ": " + str(e))
            print("voxelised", eikon.voxelize_count())
            """)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        return out.stdout.strip().splitlines()

    def test_a_batch_larger_than_the_host_holds_is_refused_with_the_numbers(self):
        for rays in (10**8, 10**9):
            lines = self.child(rays)
            self.assertEqual(len(lines), 2, lines)
            self.assertTrue(lines[0].startswith(f"RuntimeError: a trace of {rays} rays needs about "),
                            lines[0])
            self.assertIn(" GiB of host memory, ", lines[0])
            self.assertIn(" available (RLIMIT_AS); trace fewer rays at a time", lines[0])
            self.assertEqual(lines[1], "voxelised 0")

    def test_the_gpu_traces_more_rays_than_one_storage_buffer_holds(self):
        # 2^20 + 5 rays: more than lavapipe's 128 MiB storage buffers hold (two 64-byte results a
        # ray). The rays past the first 2^20 go through the sphere, the others miss it; a ray on
        # each side of the boundary equals the CPU twin's.
        r = eikon.Renderer(eikon.Scene.parse(SPHERE))
        n = (1 << 20) + 5
        origins = np.zeros((n, 3))
        origins[:, 2] = -20
        origins[:, 0] = -6.0
        origins[1 << 20:, 0] = np.linspace(0.5, 2.5, 5)
        gpu = r.trace_rays(origins, [0, 0, 1])["modes"]["o"]
        self.assertEqual(gpu["exit_point"].shape, (n, 3))
        pick = np.array([0, (1 << 20) - 1, 1 << 20, n - 1])
        cpu = r.trace_rays(origins[pick], [0, 0, 1], device="cpu")["modes"]["o"]
        np.testing.assert_allclose(gpu["exit_point"][pick], cpu["exit_point"], atol=1e-3)
        np.testing.assert_allclose(gpu["exit_direction"][pick], cpu["exit_direction"], atol=1e-3)
        self.assertEqual(list(gpu["interfaces"][pick]), [0, 0, 2, 2])
        self.assertLess(gpu["exit_direction"][n - 1][0], -0.1)  # bent towards the axis


class PolarisedTraceSettings(unittest.TestCase):
    def test_source_angle_and_bandwidth_are_checked(self):
        sc = eikon.Scene.parse(SPHERE)
        for kw, message in (
                ({"source_angle_rad": 100}, "source_angle_rad must be in (0, pi] (the angular size "
                 "of one light or environment sample), got 100"),
                ({"source_angle_rad": 0}, "source_angle_rad must be in (0, pi]"),
                ({"source_angle_rad": float("nan")}, "source_angle_rad must be in (0, pi]"),
                ({"bandwidth_nm": float("inf")}, "bandwidth_nm must be a finite number > 0 nm, "
                 "got inf"),
                ({"bandwidth_nm": -1}, "bandwidth_nm must be a finite number > 0 nm, got -1")):
            with self.subTest(kw=kw):
                with self.assertRaises(ValueError) as cm:
                    eikon.trace_polarised(sc, [0, 0, -20], [0, 0, 1], device="cpu", **kw)
                self.assertTrue(str(cm.exception).startswith(message), str(cm.exception))
        t = eikon.trace_polarised(sc, [0, 0, -20], [0, 0, 1], device="cpu", source_angle_rad=np.pi)
        self.assertEqual(t["stokes_out"].shape, (4,))


if __name__ == "__main__":
    unittest.main(verbosity=2)
