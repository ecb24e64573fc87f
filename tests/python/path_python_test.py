"""scripts/register_path_python.sh: the `python3` on PATH (a pyenv or conda python) gets this build's
module too where its ABI is the module's, else a note naming /usr/bin/python3; run against a
temporary site folder (EIKON_PTH_DIR), never the system's.

  - an interpreter of the module's extension suffix (here /usr/bin/python3 itself, told to write
    into a temporary folder) gets eikon.pth there, holding BUILD/python, and imports eikon from
    this build through it;
  - an interpreter of another Python version (a stand-in answering another suffix) gets no file,
    and the note names it, /usr/bin/python3 and the rebuild that would serve it;
  - an interpreter that imports this build's eikon already is left alone (no file, no output).
Run by CTest (python.path_python) with EIKON_PYTHON_DIR and EIKON_SOURCE_DIR.
"""
import os
import pathlib
import stat
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.environ["EIKON_SOURCE_DIR"], "scripts", "register_path_python.sh")
MODDIR = os.path.realpath(os.environ["EIKON_PYTHON_DIR"])
BUILD = os.path.dirname(MODDIR)


def register(python, site, extra_env=None):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update({"EIKON_PATH_PYTHON": python, "EIKON_PTH_DIR": site})
    env.update(extra_env or {})
    return subprocess.run(["bash", SCRIPT, BUILD], capture_output=True, text=True, env=env,
                          timeout=120)


class PathPython(unittest.TestCase):
    def test_same_abi_gets_a_pth_file(self):
        with tempfile.TemporaryDirectory() as site:
            # -S in the stand-in: the system's own eikon.pth (another build) is not read, so the
            # interpreter does not import this build's eikon before the script writes its file.
            py = pathlib.Path(site).parent / (pathlib.Path(site).name + "-python3")
            py.write_text('#!/bin/sh\nexec /usr/bin/python3 -S "$@"\n')
            py.chmod(py.stat().st_mode | stat.S_IXUSR)
            try:
                r = register(str(py), site)
            finally:
                py.unlink()
            self.assertEqual(r.returncode, 0, r.stderr)
            pth = pathlib.Path(site) / "eikon.pth"
            self.assertTrue(pth.is_file(), r.stdout + r.stderr)
            self.assertEqual(pth.read_text(), MODDIR + "\n")
            self.assertIn("registered for", r.stdout)
            check = subprocess.run(
                ["/usr/bin/python3", "-S", "-c",
                 "import site, sys; site.addsitedir(sys.argv[1]); import eikon; "
                 "print(eikon.__file__)", site],
                capture_output=True, text=True, cwd="/")
            self.assertEqual(check.returncode, 0, check.stderr)
            self.assertTrue(check.stdout.strip().startswith(MODDIR + "/"), check.stdout)

    def test_other_version_gets_a_note(self):
        with tempfile.TemporaryDirectory() as tmp:
            site = os.path.join(tmp, "site")
            fake = os.path.join(tmp, "python3")
            # Answers as a Python 3.99 would: another extension suffix, no eikon.
            with open(fake, "w") as f:
                f.write('#!/bin/sh\n'
                        'case "$*" in *"import eikon"*) exit 1 ;; esac\n'
                        'printf ".cpython-399-x86_64-linux-gnu.so\\n3.99.0\\n%s\\n" "$0-site"\n')
            os.chmod(fake, 0o755)
            r = register(fake, site)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertFalse(os.path.exists(os.path.join(site, "eikon.pth")))
            self.assertIn("cannot import eikon", r.stderr)
            self.assertIn("Python 3.99.0", r.stderr)
            self.assertIn("/usr/bin/python3", r.stderr)
            self.assertIn("-DEIKON_PYTHON_EXECUTABLE=" + fake, r.stderr)

    def test_already_importing_is_left_alone(self):
        with tempfile.TemporaryDirectory() as site:
            r = register("/usr/bin/python3", site, {"PYTHONPATH": MODDIR})
            # PYTHONPATH is unset by the script's own check; a python that imports this build's
            # eikon through its site folders is left alone. Here /usr/bin/python3 may import
            # another build's (the system eikon.pth): then the file is written, as it must be.
            self.assertEqual(r.returncode, 0, r.stderr)
            found = subprocess.run(["/usr/bin/python3", "-c", "import eikon; print(eikon.__file__)"],
                                   capture_output=True, text=True, cwd="/",
                                   env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
            if found.returncode == 0 and found.stdout.strip().startswith(MODDIR + "/"):
                self.assertEqual(os.listdir(site), [])
                self.assertEqual(r.stdout + r.stderr, "")


if __name__ == "__main__":
    unittest.main()
