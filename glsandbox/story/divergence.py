"""A pixel's story with a student's function: their trace beside the reference's, and where they part.

``glsandbox explain LESSON --pixel X,Y --exercise NAME FILE.py`` traces the pixel
twice through the numpy engine (:func:`glsandbox.story.ray_pixel.explain_ray_pixel`), once
with the exercise's reference and once with the student's function as the hit test of
its kind of node (the engine's ``hit_tests`` seam, as the exercise's lesson picture
uses it: ``intersect_sphere`` for the spheres, ``intersect_triangle`` for the meshes'
triangles), or, for the other exercises a ray calls, as its step of the traced ray
(:mod:`glsandbox.story.seams`: the triangles' plane, the boxes, culling, the reflected
ray, a light's Phong term, the shadow test, the face normal). Both use the course's simple
offset for secondary rays, as the lesson picture does. Every call of the function is
logged in the trace's order, between the engine's steps, so the two traces are two lists of facts:

- each call's answer (which node, which ray: the primary or a reflected ray at its
  depth, or a light's shadow ray, course "Gölge testi");
- each ray's nearest hit (``min_indis``: the node, its ``t``, the triangle);
- each light's shadow verdict and each hit's local colour (course "Phong boyama modeli");
- the pixel's 8-bit colour.

:func:`compare_traces` walks them side by side and names the first fact where they
part: "intersect_sphere returned t = 125 where the reference has 35". The student's
function is only called through ``caller`` (an object with the isolation's
``batch(inputs)``: their confined process, or in a notebook their own function);
nothing of theirs is imported here.
"""

from __future__ import annotations

import math
import textwrap
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.errors import SandboxError
from glsandbox.exercises.compare import describe, matches
from glsandbox.exercises.definition import Exercise
from glsandbox.exercises.lesson_view import _Calls
from glsandbox.scene import Scene
from glsandbox.story.ray_pixel import PixelTrace, ShapeTest, explain_ray_pixel
from glsandbox.story.seams import STEPS, answers_of, seams_for
from glsandbox.story.text import num, render_story, vec

__all__ = ["TRACED_KINDS", "Direct", "Divergence", "ExerciseStory", "compare_traces", "explain_with_function", "traced_kind"]

#: The tolerance two traces' numbers agree within (relative, and absolute near 0): a
#: correct geometric sphere test and the engine's stable one differ by rounding only.
REL, ABS = 1e-9, 1e-9

#: The node kind (the engine's ``hit_tests`` name) each hit-test exercise's function is the test of.
TRACED_KINDS = {"sphere": "sphere", "triangles": "triangles"}


#: Why an exercise near the ray tracer is not one of its traced steps (said when refused).
NOT_TRACED = {"image_plane": "the tracer casts its rays through the pixel centres of the lesson's camera, "
                             "not through the notes' GD(x, y) of an 800x450 picture",
              "camera_turn": "the camera is placed before a ray is cast",
              "cube_indices": "the tracer takes the mesh's triangles as built"}


def traced_kind(exercise: Exercise) -> str:
    """The step of a traced ray ``exercise``'s function is (a node kind's hit test, or one of
    :mod:`glsandbox.story.seams`'), refusing one the tracer cannot plug in."""
    if exercise.name in STEPS and exercise.name not in ("ray_sphere", "ray_triangle"):
        return exercise.name
    if exercise.lesson is None or exercise.lesson.kind not in TRACED_KINDS:
        known = ", ".join(STEPS)
        why = NOT_TRACED.get(exercise.name) or ("a matrix the rasterizer's passes use; the tracer takes the "
                                                "scene's matrices as built" if exercise.returns == "matrix4" else "")
        raise SandboxError(f"--exercise {exercise.name}: {exercise.function} is not a step of a traced ray"
                           f"{' (' + why + ')' if why else ''}; explain traces the exercises {known}")
    return TRACED_KINDS[exercise.lesson.kind]


class Direct:
    """A function called in this process (the reference, or in a notebook the student's own, in
    their kernel): the same ``batch`` as the isolation's, an exception being that input's error."""

    def __init__(self, function: Any) -> None:
        self.function = function

    def batch(self, inputs: list[tuple[Any, ...]]) -> tuple[list[Any], dict[int, str]]:
        from glsandbox.exercises.student_process import _encode  # the answers as the confined process sends them

        values: list[Any] = []
        errors: dict[int, str] = {}
        for i, args in enumerate(inputs):
            try:
                values.append(_encode(self.function(*args)))
            except Exception as exc:  # noqa: BLE001 - the function's own
                values.append(None)
                errors[i] = f"{type(exc).__name__}: {exc}"[:300]
        return values, errors


class _Seam(_Calls):
    """A caller's function as the engine's hit test of one node kind (the lesson picture's
    :class:`~glsandbox.exercises.lesson_view._Calls`: the rays taken to the function's plain
    arguments), each call logged into ``events`` (until the trace's ``end``) as ``("call", {...})``
    with its inputs and answers."""

    def __init__(self, exercise: Exercise, caller: Any, events: list[tuple[str, dict[str, Any]]]) -> None:
        super().__init__(exercise, caller)
        self.events = events

    def _answers(self, inputs: list[tuple[Any, ...]]) -> list[Any]:
        """Each input's answer, normalized: a value, or an ``error: ...`` string."""
        return answers_of(self, inputs)

    def values(self, inputs: list[tuple]) -> list[float]:
        """``t`` of each input (``inf`` for None, a failure or the wrong type), the call logged."""
        answers = self._answers(inputs)
        if inputs and not (self.events and self.events[-1][0] == "end"):
            sphere = len(inputs[0]) == 4  # (origin, direction, center, radius); a triangle's has v0, v1, v2
            self.events.append(("call", {"kind": "sphere" if sphere else "triangles", "inputs": inputs,
                                         "answers": answers, "triangles": len(inputs),  # one ray: a call a node
                                         "first": None if sphere else list(inputs[0][2])}))
        return [self._t(a) for a in answers]

    @staticmethod
    def _t(answer: Any) -> float:
        return float(answer) if isinstance(answer, (int, float)) and not isinstance(answer, bool) and answer > 0 \
            else math.inf


@dataclass
class Fact:
    """One step of a trace as compared: where it is (``where``), what (``what``) and its value."""

    where: str
    what: str
    value: Any
    call: dict[str, Any] | None = None  # a function call's inputs and answer


@dataclass
class Divergence:
    """The first fact where the two traces part: ``message`` names it with both values."""

    index: int
    where: str
    message: str
    in_function: bool
    depth: int | None = None


@dataclass
class ExerciseStory:
    """Both traces of one pixel, their facts and the first divergence (None: they agree)."""

    exercise: str
    function: str
    reference: PixelTrace
    yours: PixelTrace
    divergence: Divergence | None
    facts: int
    error: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def agree(self) -> bool:
        return self.divergence is None

    @property
    def rgba8(self) -> list[int]:
        return list(self.yours.rgba8)

    @property
    def title(self) -> str:
        return self.yours.title

    @property
    def pixel(self) -> tuple[int, int]:
        return self.yours.pixel

    def to_dict(self) -> dict[str, Any]:
        from dataclasses import asdict

        return {"exercise": self.exercise, "function": self.function, "agree": self.agree,
                "divergence": None if self.divergence is None else asdict(self.divergence),
                "facts": self.facts, "reference": self.reference.to_dict(), "yours": self.yours.to_dict(),
                "error": self.error}


def _node_of_sphere_call(world_nodes: list[Any], origin: tuple[float, ...], world_o: NDArray[np.float64]) -> Any:
    """The sphere node whose own space takes the world origin ``world_o`` to the call's ``origin``."""
    for node in world_nodes:
        if node.kind.value != "sphere":
            continue
        inv = node.inverse
        if np.allclose(inv[:3, :3] @ world_o + inv[:3, 3], origin, rtol=1e-12, atol=1e-12):
            return node
    return None


def _facts(events: list[tuple[str, dict[str, Any]]], trace: PixelTrace, nodes: list[Any], function: str
           ) -> list[Fact]:
    """A trace's events as facts, each call labelled with its ray (known at the next engine step)."""
    facts: list[Fact] = []
    pending: list[dict[str, Any]] = []
    depth = 0

    def label(where: str, world_o: NDArray[np.float64] | None, world_d: NDArray[np.float64] | None) -> None:
        for call in pending:
            for i, (args, answer) in enumerate(zip(call["inputs"], call["answers"], strict=True)):
                info = {"kind": call["kind"], "args": args, "answer": answer, "ray": where}
                if "what" in call:  # one of glsandbox.story.seams' steps
                    info["node"] = str(call.get("node_name") or "a mesh")
                    what = f"{function} {call['what'][i].format(node=info['node'])}"
                    if "light" in call:  # a light's Phong term: its light's, at the hit
                        info["ray"] = f"light {call['light']} at the hit of depth {depth}"
                    facts.append(Fact(str(info["ray"]), what, answer, info))
                    continue
                if call["kind"] == "sphere":
                    node = _node_of_sphere_call(nodes, args[0], world_o) if world_o is not None else None
                    info["node"] = node.name if node is not None else "a sphere"
                    if world_d is not None and node is not None:
                        own_d = node.inverse[:3, :3] @ world_d
                        # the call's t is along the own space's unit direction; the scene's distance
                        # along the world's unit direction is t·|d_world|/|M⁻¹d_world| (an affine map keeps t)
                        info["scale"] = float(np.linalg.norm(world_d) / np.linalg.norm(own_d))
                    what = f"{function} on {info['node']}"
                else:
                    m = max(int(call["triangles"]), 1)
                    info["triangle"] = i % m
                    info["node"] = str(call.get("node_name") or "a mesh")
                    what = f"{function} on {info['node']}, triangle {i % m}"
                facts.append(Fact(where, what, answer, info))
        pending.clear()

    for step, v in events:
        if step == "call":
            pending.append(v)
        elif step == "ray":
            depth = int(v["depth"])
            where = "the primary ray" if depth == 0 else f"the ray of depth {depth}"
            o = np.asarray(v["origin"], dtype=np.float64).reshape(-1, 3)[0]
            d = np.asarray(v["direction"], dtype=np.float64).reshape(-1, 3)[0]
            label(where, o, d)
            node = int(v["node"][0])
            hit = None if node < 0 else (nodes[node].name, float(v["t"][0]), int(v["tri"][0]))
            facts.append(Fact(where, "the nearest hit (min_indis)", hit))
        elif step == "surface":  # what the hit's surface asked (a face normal)
            label(f"the hit at depth {depth}", None, None)
        elif step == "light":
            index = int(v["index"])
            where = f"the shadow ray towards light {index} (depth {depth})"
            start = None if v.get("start") is None else np.asarray(v["start"], dtype=np.float64)[0]
            label(where, start, None if start is None else trace_light(trace, index) - start)
            if v.get("blocked") is not None:
                facts.append(Fact(where, "in shadow", bool(v["blocked"][0])))
        elif step == "local":
            facts.append(Fact(f"the hit at depth {depth}", "the local colour", [float(c) for c in
                                                                                np.asarray(v["local"])[0]]))
    facts.append(Fact("the pixel", "the 8-bit colour", list(trace.rgba8)))
    return facts


def trace_light(trace: PixelTrace, index: int) -> NDArray[np.float64]:
    """Light ``index``'s position, from the first bounce that lists it."""
    for bounce in trace.bounces:
        for light in bounce.lights:
            if light.index == index:
                return np.asarray(light.position, dtype=np.float64)
    return np.zeros(3)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    if isinstance(a, tuple) and isinstance(b, tuple) and len(a) == 3 and isinstance(a[0], str):
        return a[0] == b[0] and a[2] == b[2] and matches(a[1], b[1], REL, ABS)
    if a is None or b is None:
        return a is b
    return matches(a, b, REL, ABS)


def _say(value: Any) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"t = {num(value)}"
    if value is None:
        return "None"
    return describe(value)


def _arg(a: Any) -> str:
    if isinstance(a, list):  # in_shadow's triangles
        return f"[{len(a)} triangles]"
    return vec(a) if isinstance(a, tuple) else num(a)


def _call_message(function: str, mine: Fact, ref: Fact) -> str:
    info, other = mine.call or {}, ref.call or {}
    got, want = info.get("answer"), other.get("answer")
    args = ", ".join(_arg(a) for a in info.get("args", ()))
    if info.get("kind") not in ("sphere", "triangles"):  # glsandbox.story.seams' steps
        def say(v: Any, fine: bool = False) -> str:
            if fine and isinstance(v, (tuple, float)):  # they part beyond six digits
                return "(" + ", ".join(f"{x:.12g}" for x in v) + ")" if isinstance(v, tuple) else f"t = {v:.12g}"
            return describe(v) if isinstance(v, (bool, tuple)) else _say(v)
        fine = say(got) == say(want)
        return (f"{function} returned {say(got, fine)} where the reference has "
                f"{say(want, fine).removeprefix('t = ')} "
                f"({mine.what.removeprefix(function).strip()}, {mine.where}); called as {function}({args})")
    text = (f"{function} returned {_say(got)} where the reference has {_say(want).removeprefix('t = ')} "
            f"({info.get('node')}, {mine.where})")
    scale = info.get("scale")
    if info.get("kind") == "sphere" and scale:
        def world(v: Any) -> str:
            return f"t = {num(v * scale)}" if isinstance(v, float) else _say(v)
        text = (f"{function} returned {world(got)} where the reference has {world(want).removeprefix('t = ')} "
                f"({info.get('node')}, {mine.where}); called in the sphere's own space, where it is the unit "
                f"sphere: {function}({args}) = {_say(got)}, the reference {_say(want)}")
    elif info.get("kind") == "triangles":
        text += f"; called as {function}({args})"
    return text


def compare_traces(mine: list[Fact], ref: list[Fact], function: str) -> Divergence | None:
    """The first fact where ``mine`` and ``ref`` part, named with both values; None when they agree."""
    for i, (a, b) in enumerate(zip(mine, ref, strict=False)):
        if a.where != b.where or a.what != b.what:
            return Divergence(i, a.where, f"the traces take different paths: yours has {a.what} ({a.where}) "
                              f"where the reference has {b.what} ({b.where})", a.call is not None or b.call is not None)
        if not _same(a.value, b.value):
            if a.call is not None:
                return Divergence(i, a.where, _call_message(function, a, b), True)
            if a.what.startswith("the nearest hit"):
                def hit(v: Any) -> str:
                    return "nothing" if v is None else f"{v[0]} at t = {num(v[1])}"
                message = f"{a.where} hits {hit(a.value)} where the reference hits {hit(b.value)}"
            else:
                message = f"{a.what} of {a.where} is {_say(a.value)} where the reference has {_say(b.value)}"
            return Divergence(i, a.where, message, False)
    if len(mine) != len(ref):
        i = min(len(mine), len(ref))
        longer = "yours" if len(mine) > len(ref) else "the reference's"
        rest = (mine if len(mine) > len(ref) else ref)[i]
        return Divergence(i, rest.where, f"{longer} trace goes on: {rest.what} ({rest.where})", rest.call is not None)
    return None


def _tested_by_function(trace: PixelTrace, facts: list[Fact], kind: str, function: str) -> None:
    """The student's trace's shape tests of the replaced kind say what their function returned."""
    engine_kind = "sphere" if kind == "sphere" else "mesh"
    for bounce in trace.bounces:
        where = "the primary ray" if bounce.depth == 0 else f"the ray of depth {bounce.depth}"
        answers = {f.call["node"]: f.call["answer"] for f in facts if f.call and f.where == where}
        for k, test in enumerate(bounce.tests):
            if test.kind != engine_kind or test.verdict == "box":
                continue
            said = f"t = {num(test.t)} along the ray as cast" if test.t is not None else \
                _say(answers.get(test.node)) + " (no hit)"
            bounce.tests[k] = ShapeTest(test.node, test.kind, "hit" if test.t is not None else "miss",
                                        f"your {function} gave {said}", test.t, test.triangle)


def explain_with_function(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], exercise: Exercise,
                          caller: Any, title: str = "") -> ExerciseStory:
    """Pixel ``pixel`` of ``scene`` traced with ``exercise``'s reference and with ``caller``'s function
    (see the module docstring)."""
    kind = traced_kind(exercise)

    def plugged(function: Any, events: list[tuple[str, dict[str, Any]]]) -> tuple[dict[str, Any], Any]:
        other = seams_for(exercise, function, events)
        if other is not None:
            return other
        hit = _Seam(exercise, function, events)
        return {kind: getattr(hit, kind)}, hit

    ref_events: list[tuple[str, dict[str, Any]]] = []
    tests, _ = plugged(Direct(exercise.reference), ref_events)
    reference = explain_ray_pixel(scene, size, pixel, title, hit_tests=tests, simple=True, events=ref_events,
                                  traced=True)
    my_events: list[tuple[str, dict[str, Any]]] = []
    tests, seam = plugged(caller, my_events)
    yours = explain_ray_pixel(scene, size, pixel, title, hit_tests=tests, simple=True, events=my_events, traced=True)
    reference.renderer = yours.renderer = "ray_numpy"  # both traced by the numpy engine, as the lesson picture is
    world = _world(scene, reference.viewport)
    nodes = list(world.nodes)
    _name_meshes(world, ref_events, my_events)
    ref_facts = _facts(ref_events, reference, nodes, exercise.function)
    my_facts = _facts(my_events, yours, nodes, exercise.function)
    if kind in TRACED_KINDS:
        _tested_by_function(yours, my_facts, kind, exercise.function)
    divergence = compare_traces(my_facts, ref_facts, exercise.function)
    return ExerciseStory(exercise.name, exercise.function, reference, yours, divergence, len(my_facts), seam.error)


def _world(scene: Scene, viewport: int) -> Any:
    """The numpy engine's World of ``viewport`` (its nodes, their triangles), as the traces built it."""
    from glsandbox.frame import single_viewport
    from glsandbox.raytrace import numpy_engine

    return numpy_engine._world_of(single_viewport(scene, viewport), 0, True, False)[0]


def _name_meshes(world: Any, *event_lists: list[tuple[str, dict[str, Any]]]) -> None:
    """Each triangle call's node, by its first triangle's first vertex (the node's rows of the World)."""
    for events in event_lists:
        for step, v in events:
            if step == "call" and v.get("first") is not None:
                for node in world.nodes:
                    if node.kind.triangles and node.count and np.array_equal(world.v0[node.start], v["first"]):
                        v["node_name"] = node.name
                        break


# --- the two traces side by side -----------------------------------------------------------

COLUMN = 60


def _blocks(text: str) -> list[list[str]]:
    """A story's lines grouped by numbered step (a step and its indented lines)."""
    blocks: list[list[str]] = []
    for line in text.split("\n"):
        if not blocks or (line[:1].isdigit() and ". " in line[:5]):
            blocks.append([line])
        else:
            blocks[-1].append(line)
    return blocks


def _wrapped(block: list[str]) -> list[str]:
    out: list[str] = []
    for line in block:
        indent = len(line) - len(line.lstrip(" "))
        out.extend(textwrap.wrap(line, COLUMN, subsequent_indent=" " * (indent + 3), drop_whitespace=True) or [""])
    return out


def side_by_side(left: str, right: str, titles: tuple[str, str]) -> list[str]:
    """Two stories in two columns, step beside step (the shorter block padded)."""
    lines = [f"{titles[0]:<{COLUMN}} │ {titles[1]}", f"{'─' * COLUMN}─┼─{'─' * COLUMN}"]
    a, b = _blocks(left), _blocks(right)
    for k in range(max(len(a), len(b))):
        wa = _wrapped(a[k]) if k < len(a) else []
        wb = _wrapped(b[k]) if k < len(b) else []
        for i in range(max(len(wa), len(wb))):
            x = wa[i] if i < len(wa) else ""
            y = wb[i] if i < len(wb) else ""
            mark = "│" if x == y else "┃"
            lines.append(f"{x:<{COLUMN}} {mark} {y}".rstrip())
    return lines


def render_exercise_story(story: ExerciseStory) -> str:
    """The verdict first, then the two traces side by side (a heavy bar where a line differs)."""
    if story.divergence is None:
        head = [f"{story.function}: your trace and the reference's agree at every step ({story.facts} steps, "
                "every call of your function among them)"]
    else:
        d = story.divergence
        head = [f"first difference: {d.message}"]
    if story.error:
        head.append(f"note: {story.error}")
    columns = side_by_side(render_story(story.yours), render_story(story.reference),
                           (f"yours ({story.function} from your file)", "the reference"))
    return "\n".join([*head, "", *columns])
