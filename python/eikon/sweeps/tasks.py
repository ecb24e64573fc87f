"""The tasks a sweep runs on each item, by name: "render" (Renderer.render) and "gem"
(eikon.gem). A task checks its options when the sweep is read, prepares a session
for a scene (the part a worker keeps warm) and runs one item on it, returning its figures (the
results.csv columns) and its images ({name: (H, W, 3) float32 linear sRGB}, written beside it).

A new task is a Task subclass in TASKS: its options checked in __init__ (TaskError naming the
option), prepare(scene) and run(session, scene).
"""
import numbers
import os

import numpy as np


class TaskError(ValueError):
    """A task or option the sweep refuses; `option` names it (None: the task's kind)."""

    def __init__(self, what, option=None):
        super().__init__(what)
        self.option = option


class Task:
    kind = ""

    def __init__(self, options):
        self.options = dict(options)

    def spec(self):
        """What the task is, for the items' keys: a changed option makes every item new."""
        return {"kind": self.kind, **self.options}

    @staticmethod
    def session_part(scene):
        """The part of an item's scene (a dict) a session depends on: all of it but the camera,
        which renders read at each call (a turntable moves only the camera)."""
        return {k: v for k, v in scene.items() if k != "camera"}

    def prepare(self, scene):
        return scene

    def run(self, session, scene):
        raise NotImplementedError


def _render_keywords():
    import eikon
    return {s["keyword"]: s for s in eikon.settings() if "Renderer.render" in s["defaults"]}


class RenderTask(Task):
    """Renderer.render with the task's options (its keywords: eikon.settings(), and light,
    light_cache, march as {step_voxels, integrator, ...}); "exposure" is the PNG preview's.
    Figures: the image's mean R, G, B and mean and highest luminance (Rec. 709 Y)."""

    kind = "render"
    OTHERS = {"light": bool, "light_cache": bool, "march": dict, "exposure": numbers.Real}

    def __init__(self, options):
        super().__init__(options)
        keywords = _render_keywords()
        for name, value in self.options.items():
            if name in ("layers", "progress"):
                raise TaskError(f"'{name}' is not an option of a sweep's render", name)
            if name in self.OTHERS:
                if not isinstance(value, self.OTHERS[name]) or isinstance(value, bool) != (
                        self.OTHERS[name] is bool):
                    raise TaskError(f"expected a {self.OTHERS[name].__name__}", name)
                continue
            if name not in keywords:
                known = ", ".join(sorted(set(keywords) - {"layers"} | set(self.OTHERS)))
                raise TaskError(f"unknown option of the render task (known: {known})", name)
            self._check_kind(name, value, keywords[name])

    @staticmethod
    def _check_kind(name, value, setting):
        kind = setting["kind"]
        ok = {"integer": isinstance(value, int) and not isinstance(value, bool),
              "number": isinstance(value, numbers.Real) and not isinstance(value, bool),
              "flag": isinstance(value, bool),
              "choice": value in setting["choices"],
              "text": isinstance(value, str)}.get(kind, True)
        if not ok:
            what = f"one of {', '.join(setting['choices'])}" if kind == "choice" else f"a {kind}"
            raise TaskError(f"expected {what}, got {value!r}", name)

    def prepare(self, scene):
        import eikon
        return eikon.Renderer(scene)

    def run(self, session, scene):
        import eikon
        kw = {k: v for k, v in self.options.items() if k != "exposure"}
        if "threads" not in kw and os.environ.get("EIKON_SWEEP_THREADS", "").isdigit():
            kw["threads"] = int(os.environ["EIKON_SWEEP_THREADS"])  # the worker's share of cores
        if "march" in kw:
            kw["march"] = eikon.MarchSettings(**kw["march"])
        rgb = np.asarray(session.render(progress=False, **kw), dtype=np.float32)
        y = rgb @ np.array([0.2126, 0.7152, 0.0722])
        figures = {"mean_r": float(rgb[..., 0].mean()), "mean_g": float(rgb[..., 1].mean()),
                   "mean_b": float(rgb[..., 2].mean()), "mean_luminance": float(y.mean()),
                   "max_luminance": float(y.max())}
        return figures, {"image": rgb}


# results.csv's own columns: a task's figure of the same name is left out.
RESERVED = ("index", "seconds", "task_seconds", "worker", "warm", "error")


class GemTask(Task):
    """eikon.gem(scene, **options) (`eikon gem`'s figures; its keywords: tilts, width, height,
    spp, wavelengths, object, threads, keep_images, seed). Figures: its top-level numbers (brightness,
    fire, scintillation, windowing, extinction, contrast_change, object); with keep_images its
    pictures are the images (dome_K and spot_K per tilt, aset, idealscope, lightbox)."""

    kind = "gem"
    OPTIONS = {"tilts": (list, str), "width": int, "height": int, "spp": int, "wavelengths": int,
               "object": int, "threads": int, "keep_images": bool, "seed": int,
               "exposure": numbers.Real}

    def __init__(self, options):
        super().__init__(options)
        for name, value in self.options.items():
            if name not in self.OPTIONS:
                known = ", ".join(sorted(self.OPTIONS))
                raise TaskError(f"unknown option of the gem task (known: {known})", name)
            want = self.OPTIONS[name]
            types = want if isinstance(want, tuple) else (want,)
            if not isinstance(value, types) or isinstance(value, bool) != (want is bool):
                what = " or ".join(t.__name__ for t in types)
                raise TaskError(f"expected {what}, got {value!r}", name)

    def run(self, session, scene):
        import eikon
        kw = {k: v for k, v in self.options.items() if k != "exposure"}
        if "threads" not in kw and os.environ.get("EIKON_SWEEP_THREADS", "").isdigit():
            kw["threads"] = int(os.environ["EIKON_SWEEP_THREADS"])  # the worker's share of cores
        out = eikon.gem(scene, **kw)
        figures = {name: float(value) for name, value in out.items()
                   if name not in RESERVED and isinstance(value, numbers.Real)
                   and not isinstance(value, bool)}
        images = {name: np.asarray(rgb, dtype=np.float32)
                  for name, rgb in out.get("images", {}).items()}
        return figures, images


TASKS = {"render": RenderTask, "gem": GemTask}


def make(kind, options):
    if kind not in TASKS:
        raise TaskError(f"unknown task '{kind}' (known: {', '.join(TASKS)})")
    return TASKS[kind](options)
