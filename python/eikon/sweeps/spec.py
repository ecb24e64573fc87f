"""A sweep file (SWEEP.json) read and checked, and its items: the cartesian product of "vary".

    {"scene": "scenes/glass_sphere.json",          # a path (relative to SWEEP.json) or an object
     "task": {"kind": "render", "width": 32, "height": 24, "spp": 1},
     "vary": {"/camera/position": [[0, 0, -60], [30, 0, -52]],
              "/objects/0/material": ["glass", "N-SF11"]}}

Each key of "vary" is a JSON pointer (RFC 6901) into the scene; its list holds the values it takes.
Every error is a SweepError whose text names the file and the JSON path in it.
"""
import copy
import hashlib
import itertools
import json
import os

from . import tasks


class SweepError(ValueError):
    """A sweep file the sweep refuses: "FILE: /json/path: what"."""


def _escape(token):
    return str(token).replace("~", "~0").replace("/", "~1")


def pointer_tokens(pointer):
    """The tokens of a JSON pointer ("/a/0/b~1c" → ["a", "0", "b/c"]); ValueError if malformed."""
    if not isinstance(pointer, str) or not pointer.startswith("/"):
        raise ValueError(f"'{pointer}' is not a JSON pointer (it must start with '/')")
    tokens = pointer[1:].split("/")
    for t in tokens:
        if "~" in t.replace("~0", "").replace("~1", ""):
            raise ValueError(f"'{pointer}' has a '~' not followed by 0 or 1")
    return [t.replace("~1", "/").replace("~0", "~") for t in tokens]


def _step(node, token, where):
    if isinstance(node, list):
        if not token.isdigit() or (len(token) > 1 and token[0] == "0"):
            raise ValueError(f"{where} is a list; '{token}' is not an index")
        if int(token) >= len(node):
            n = len(node)
            raise ValueError(f"{where} has {n} element{'' if n == 1 else 's'}, no element {token}")
        return int(token)
    if isinstance(node, dict):
        return token
    raise ValueError(f"{where} is a {type(node).__name__}, it has no '{token}'")


def set_pointer(doc, pointer, value):
    """Set the value `pointer` names in `doc` (in place). Every step but the last must exist; the
    last may name a new key of an object, not a new element of a list."""
    tokens = pointer_tokens(pointer)
    node, where = doc, ""
    for i, token in enumerate(tokens):
        key = _step(node, token, where or "the scene")
        if i == len(tokens) - 1:
            node[key] = copy.deepcopy(value)
            return
        if isinstance(node, dict) and key not in node:
            raise ValueError(f"the scene has no {where}/{_escape(token)}")
        node, where = node[key], where + "/" + _escape(token)


class Item:
    """One render of the sweep: its index in the product, the values of the varied pointers, the
    scene they make and a key (SHA-256 of the scene, its origin and the task) that names it across
    runs: an item whose key has a record in the output folder is done."""

    def __init__(self, index, values, scene, origin, task):
        self.index = index
        self.values = values
        self.scene = scene
        self.origin = origin
        text = json.dumps({"scene": scene, "origin": origin, "task": task}, sort_keys=True)
        self.key = hashlib.sha256(text.encode()).hexdigest()

    @property
    def stem(self):
        return f"item{self.index:05d}-{self.key[:12]}"


class Sweep:
    """A checked sweep file: scene (a dict), origin (the scene's path, for relative paths and
    messages), task (the registry's Task), vary ({pointer: [values]})."""

    def __init__(self, path=None, spec=None):
        self.file = str(path) if path is not None else "<python>"
        if spec is None:
            spec = self._read_json(self.file, "sweep file")
        self.base = os.path.dirname(os.path.abspath(self.file)) if path is not None else os.getcwd()
        if not isinstance(spec, dict):
            self._fail("", f"expected an object, got {type(spec).__name__}")
        for key in spec:
            if key not in ("scene", "task", "vary", "description"):
                self._fail("/" + _escape(key), "unknown key (expected scene, task, vary)")
        self._read_scene(spec)
        self._read_task(spec)
        self._read_vary(spec)

    def _fail(self, where, what):
        raise SweepError(f"{self.file}: {where or '/'}: {what}")

    def _read_json(self, path, what):
        try:
            with open(path, encoding="utf-8") as f:
                return json.load(f)
        except json.JSONDecodeError as e:
            raise SweepError(f"{path}: line {e.lineno}: {e.msg}") from None
        except (OSError, UnicodeDecodeError) as e:
            raise SweepError(f"{path}: cannot read the {what}: {getattr(e, 'strerror', None) or e}")

    def _read_scene(self, spec):
        scene = spec.get("scene")
        if isinstance(scene, str):
            self.origin = os.path.normpath(os.path.join(self.base, scene))
            if not os.path.isfile(self.origin):
                self._fail("/scene", f"no scene file '{self.origin}'")
            self.scene = self._read_json(self.origin, "scene")
            if not isinstance(self.scene, dict):
                raise SweepError(f"{self.origin}: /: expected an object")
        elif isinstance(scene, dict):
            self.scene, self.origin = scene, os.path.join(self.base, "<sweep scene>")
        else:
            self._fail("/scene", "expected a scene file's path or a scene object")

    def _read_task(self, spec):
        task = spec.get("task")
        if isinstance(task, str):
            task = {"kind": task}
        if not isinstance(task, dict) or not isinstance(task.get("kind"), str):
            self._fail("/task", 'expected {"kind": "render"|"gem", options...} or "render"')
        try:
            self.task = tasks.make(task["kind"], {k: v for k, v in task.items() if k != "kind"})
        except tasks.TaskError as e:
            self._fail(f"/task/{_escape(e.option)}" if e.option else "/task/kind", str(e))

    def _read_vary(self, spec):
        vary = spec.get("vary", {})
        if not isinstance(vary, dict):
            self._fail("/vary", "expected an object of JSON pointers into the scene")
        probe = copy.deepcopy(self.scene)
        for pointer, values in vary.items():
            where = "/vary/" + _escape(pointer)
            if not isinstance(values, list) or not values:
                self._fail(where, "expected a non-empty list of values")
            try:
                for value in values:
                    set_pointer(copy.deepcopy(probe), pointer, value)
            except ValueError as e:
                self._fail(where, str(e))
        self.vary = vary

    def items(self):
        """Every item, in the order of the product (the last pointer varies fastest)."""
        pointers = list(self.vary)
        out = []
        for index, combo in enumerate(itertools.product(*(self.vary[p] for p in pointers))):
            scene = copy.deepcopy(self.scene)
            for pointer, value in zip(pointers, combo):
                set_pointer(scene, pointer, value)
            out.append(Item(index, dict(zip(pointers, combo)), scene, self.origin,
                            self.task.spec()))
        return out
