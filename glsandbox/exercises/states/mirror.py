"""The ``mirror_states`` exercise: the mirror room drawn with the student's state tables, graded by a leak map.

Course section "The stencil Test: MarkMirrorDSS, DrawReflectionDSS" (and
``CullClockwise``, the planar shadow's no-double-blend stencil and
``shadowOffsetY``). The student fills the tutorials' tables
(:mod:`glsandbox.exercises.states.tables` maps their Direct3D names to the
plan's GL states); the lesson ``mirror`` (stencil mirror, stencil shadow,
polygon offset off so the lift alone keeps the shadow above the floor) is
planned as usual and its planar passes take their states from the tables
(:func:`apply_tables`). The frame is drawn twice, with the plan's own states
and with the student's, each pass read back, and every pixel classified
(:func:`leak_map`): the reference tables give an empty map.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from glsandbox.exercises.states.tables import DepthStencil, StateTables, parse_tables
from glsandbox.passes.plan_parts import Pass, StencilState

__all__ = ["CLASSES", "MISTAKES", "REFERENCE_SOURCE", "LeakMap", "apply_tables", "leak_map", "reference_tables",
           "starter", "render_with"]

SIZE = (256, 256)
#: The lesson's settings the exercise grades with.
SETTINGS = ("mirror=stencil", "shadow=on", "offset=False")

#: The tutorials' tables (Frank Luna's mirror demo, as the course gives them).
REFERENCE_SOURCE = '''\
"""The state tables of the stencil mirror and its planar shadow (course "The stencil Test").

Fill in every ... with a Direct3D 11 name (D3D11_COMPARISON_EQUAL, D3D11_STENCIL_OP_INCR,
D3D11_CULL_BACK, D3D11_BLEND_SRC_ALPHA, D3D11_DEPTH_WRITE_MASK_ZERO, ...), True/False or a number.
This file is data: only these assignments of literals, nothing else (it is never run).
Check it with: glsandbox exercise check mirror_states THIS_FILE.py
"""

# MarkMirrorDSS: the glass's visible pixels get the stencil value 1; nothing else changes.
MARK_MIRROR_DSS = {
    "DepthEnable": True,
    "DepthWriteMask": "D3D11_DEPTH_WRITE_MASK_ZERO",
    "StencilEnable": True,
    "StencilReadMask": 0xFF,
    "StencilWriteMask": 0xFF,
    "StencilFunc": "D3D11_COMPARISON_ALWAYS",
    "StencilPassOp": "D3D11_STENCIL_OP_REPLACE",
    "StencilRef": 1,
}

# DrawReflectionDSS: the reflected room only where the stencil holds 1.
DRAW_REFLECTION_DSS = {
    "DepthEnable": True,
    "DepthWriteMask": "D3D11_DEPTH_WRITE_MASK_ALL",
    "StencilEnable": True,
    "StencilReadMask": 0xFF,
    "StencilWriteMask": 0xFF,
    "StencilFunc": "D3D11_COMPARISON_EQUAL",
    "StencilPassOp": "D3D11_STENCIL_OP_KEEP",
    "StencilRef": 1,
}

# CullClockwiseRS: the reflected pass's rasterizer (the reflection matrix has determinant -1).
REFLECTED_RASTERIZER = {
    "CullMode": "D3D11_CULL_BACK",
    "FrontCounterClockwise": True,
}

# TransparentBS: the shadow is black at alpha 0.5 over the floor.
SHADOW_BLEND = {
    "BlendEnable": True,
    "SrcBlend": "D3D11_BLEND_SRC_ALPHA",
    "DestBlend": "D3D11_BLEND_INV_SRC_ALPHA",
}

# NoDoubleBlendDSS: a pixel is darkened only while its stencil is 0, then counted up.
SHADOW_DSS = {
    "DepthEnable": True,
    "DepthWriteMask": "D3D11_DEPTH_WRITE_MASK_ZERO",
    "StencilEnable": True,
    "StencilReadMask": 0xFF,
    "StencilWriteMask": 0xFF,
    "StencilFunc": "D3D11_COMPARISON_EQUAL",
    "StencilPassOp": "D3D11_STENCIL_OP_INCR",
    "StencilRef": 0,
}

# shadowOffsetY: how far the flattened cube is lifted along the floor's normal (world units).
SHADOW_LIFT = 0.005
'''


def reference_tables() -> StateTables:
    """The tutorials' tables, read as a student's file is."""
    return parse_tables(REFERENCE_SOURCE, "reference")


def starter() -> str:
    """The starting file: the tables with every value a blank (``...``)."""
    blanked = re.sub(r'^(    "\w+": ).*,$', r"\1...,", REFERENCE_SOURCE, flags=re.M)
    return re.sub(r"^SHADOW_LIFT = .*$", "SHADOW_LIFT = ...", blanked, flags=re.M)


# --- the tables in the plan ------------------------------------------------------

def _stencil(table: DepthStencil, needed: bool) -> StencilState | None:
    """A depth-stencil table's stencil state; without ``StencilEnable`` none, or (``needed``:
    the marking pass, whose runner always sets one) one that passes and writes nothing."""
    if not table.stencil:
        return StencilState("always", 0) if needed else None
    return StencilState(table.test, table.ref, mask=table.read_mask, write_mask=table.write_mask,
                        on_pass=table.on_pass)


def apply_tables(step: Pass, tables: StateTables) -> Pass:
    """``step`` with the states the tables give it (the planar passes; any other as it is)."""
    if step.kind == "mark_mirror":
        t = tables.mark_mirror
        return dataclasses.replace(step, depth_test=t.depth_test, depth_write=t.depth_write,
                                   stencil=_stencil(t, True))
    if step.kind == "reflection":
        t, r = tables.draw_reflection, tables.reflected_rasterizer
        # GL culls back faces by the front-face rule: culling front faces is culling back faces
        # under the other rule; FrontCounterClockwise=True is the flipped rule ("cw" here).
        flipped = r.ccw_front != (r.cull == "front")
        draws = step.draws if r.cull != "none" else tuple(dataclasses.replace(d, cull_back_faces=False)
                                                          for d in step.draws)
        return dataclasses.replace(step, depth_test=t.depth_test, depth_write=t.depth_write,
                                   stencil=_stencil(t, False), front_face="cw" if flipped else "ccw",
                                   draws=draws)
    if step.kind == "planar_shadow":
        t, b = tables.shadow, tables.shadow_blend
        return dataclasses.replace(step, depth_test=t.depth_test, depth_write=t.depth_write,
                                   stencil=_stencil(t, False),
                                   blend=(b.source, b.destination) if b.enabled else ("one", "zero"))
    return step


# --- drawing and reading back ------------------------------------------------------

@dataclass
class Capture:
    """The frame's colour (H, W, 3) after each planar pass, by kind, and the stencil after the marking."""

    colors: dict[str, NDArray[np.uint8]]
    mirror: NDArray[np.bool_]
    frame: NDArray[np.uint8]


def _scene(lift: float | None) -> Any:
    """The graded room; ``lift`` the shadow's (None: the lesson's own)."""
    from glsandbox.lesson import find_lesson

    scene = find_lesson("mirror").from_settings(SETTINGS).scene()
    assert scene.planar_shadow is not None
    if lift is None:
        return scene
    shadow = scene.planar_shadow
    if lift < 0:
        # A shadow lifted against the normal (the scene refuses a negative lift): the casters
        # flattened onto the floor's plane moved down by |lift| (n·x + d + |lift|·|n| = 0).
        a, b, c, d = shadow.plane
        lowered = (a, b, c, d - lift * float(np.linalg.norm((a, b, c))))
        return dataclasses.replace(scene, planar_shadow=dataclasses.replace(shadow, plane=lowered, lift=0.0))
    return dataclasses.replace(scene, planar_shadow=dataclasses.replace(shadow, lift=lift))


def render_with(renderer: Any, tables: StateTables | None) -> Capture:
    """The mirror room drawn on ``renderer`` (a :class:`~glsandbox.frame.FrameRenderer`) with
    ``tables`` (None: the plan's own states and lift), read back after each planar pass."""
    from glsandbox.plan import plan

    scene = _scene(tables.shadow_lift if tables is not None else None)
    frame_plan = plan(scene)
    if tables is not None:
        frame_plan = dataclasses.replace(frame_plan, passes=tuple(apply_tables(s, tables) for s in frame_plan.passes))
    host = renderer.host
    raw = host.raw
    host.make_current()
    colors: dict[str, NDArray[np.uint8]] = {}
    mirror = np.zeros((SIZE[1], SIZE[0]), dtype=bool)

    def after_pass(index: int, step: Pass) -> None:
        fbo = raw.bound_framebuffer()
        colors[step.kind] = raw.read_pixels(fbo, SIZE, "color")[..., :3].copy()
        if step.kind == "mark_mirror":
            mirror[:] = raw.read_pixels(fbo, SIZE, "stencil").reshape(SIZE[1], SIZE[0]) != 0

    target = renderer.target(SIZE, frame_plan.buffers)
    renderer.executor.render(scene, target.framebuffer, SIZE, frame_plan, after_pass=after_pass)
    frame = np.array(target.read())[..., :3]
    return Capture(colors, mirror, frame)


# --- the leak map -------------------------------------------------------------------

#: The leak map's classes: (name, colour); 0 is "as the reference".
CLASSES: tuple[tuple[str, tuple[int, int, int]], ...] = (
    ("as the reference", (0, 0, 0)),
    ("reflection outside the mirror", (255, 40, 40)),
    ("reflection wrong inside the mirror", (255, 200, 0)),
    ("reflection missing in the mirror", (40, 120, 255)),
    ("shadow pixels blended twice", (200, 0, 255)),
    ("shadow pixels missing", (0, 220, 220)),
    ("other differences", (255, 255, 255)),
)
#: A change of a pixel by a pass: more than this in some channel (8-bit levels).
CHANGED = 2


def _changed(after: NDArray[np.uint8], before: NDArray[np.uint8]) -> NDArray[np.bool_]:
    return np.any(np.abs(after.astype(np.int16) - before.astype(np.int16)) > CHANGED, axis=2)


@dataclass
class LeakMap:
    """Each pixel's class (an index into :data:`CLASSES`), top row first, and the counts."""

    classes: NDArray[np.uint8]
    reference_frame: NDArray[np.uint8]

    def counts(self) -> dict[str, int]:
        """Pixels of each class but the first."""
        return {name: int(np.count_nonzero(self.classes == k)) for k, (name, _) in enumerate(CLASSES) if k}

    @property
    def empty(self) -> bool:
        return not np.any(self.classes)

    def picture(self) -> NDArray[np.uint8]:
        """The reference frame dimmed to a quarter, each leaking pixel in its class's colour."""
        out = (self.reference_frame // 4).astype(np.uint8)
        for k, (_, color) in enumerate(CLASSES):
            if k:
                out[self.classes == k] = color
        return out


def leak_map(reference: Capture, student: Capture) -> LeakMap:
    """Classify every pixel of the student's frame against the reference's, pass by pass: where
    the reflection pass drew outside the reference's mirror, drew wrongly or not at all inside it,
    where the shadow darkened a pixel more than the reference (blended twice) or did not darken
    it, and any other difference of the frames."""
    r, s = reference.colors, student.colors
    classes = np.zeros(reference.mirror.shape, dtype=np.uint8)
    inside = reference.mirror
    r_refl = _changed(r["reflection"], r["mark_mirror"])
    s_refl = _changed(s["reflection"], s["mark_mirror"])
    wrong = _changed(s["reflection"], r["reflection"])
    r_shadow = _changed(r["planar_shadow"], r["mirror_surface"])
    s_shadow = _changed(s["planar_shadow"], s["mirror_surface"])
    darker = (r["planar_shadow"].astype(np.int16).sum(axis=2) - s["planar_shadow"].astype(np.int16).sum(axis=2)
              > 3 * CHANGED)
    other = _changed(student.frame, reference.frame)
    order = [
        (6, other),
        (5, r_shadow & ~s_shadow),
        (4, (r_shadow | s_shadow) & darker),
        (2, inside & s_refl & wrong),
        (3, inside & r_refl & ~s_refl),
        (1, ~inside & s_refl),
    ]
    for k, where in order:  # the later, more telling class wins a pixel
        classes[where] = k
    return LeakMap(classes, reference.frame)


# --- the known mistakes ------------------------------------------------------------

@dataclass(frozen=True)
class StateMistake:
    """A known wrong table, the leak-map class it shows as, and the hint that names it."""

    name: str
    hint: str
    shows_as: int
    change: Any  # StateTables -> StateTables


def _dss(tables: StateTables, which: str, **changes: Any) -> StateTables:
    return dataclasses.replace(tables, **{which: dataclasses.replace(getattr(tables, which), **changes)})


MISTAKES: tuple[StateMistake, ...] = (
    StateMistake("stencil_always", "DRAW_REFLECTION_DSS's StencilFunc is still D3D11_COMPARISON_ALWAYS: the reflected "
                 "pass must pass only where MarkMirrorDSS wrote the reference (D3D11_COMPARISON_EQUAL, ref 1)",
                 1, lambda t: _dss(t, "draw_reflection", test="always")),
    StateMistake("winding_not_flipped", "REFLECTED_RASTERIZER keeps the normal winding: the reflection matrix has "
                 "determinant -1 and turns every triangle's winding, so the front-face rule must flip "
                 "(FrontCounterClockwise = True, CullClockwise) or the mirror shows the back faces",
                 2, lambda t: dataclasses.replace(t, reflected_rasterizer=dataclasses.replace(
                     t.reflected_rasterizer, ccw_front=False))),
    StateMistake("mirror_writes_depth", "MARK_MIRROR_DSS writes depth (D3D11_DEPTH_WRITE_MASK_ALL): the glass's depth "
                 "then hides the reflection, which lies behind the glass; the marking pass writes only the stencil",
                 3, lambda t: _dss(t, "mark_mirror", depth_write=True)),
    StateMistake("no_double_blend_missing", "SHADOW_DSS does not count the stencil up (StencilPassOp KEEP, or no "
                 "stencil): the flattened cube covers each shadow pixel twice and it is blended twice; test EQUAL 0 "
                 "and D3D11_STENCIL_OP_INCR so a pixel darkens once",
                 4, lambda t: _dss(t, "shadow", on_pass="keep")),
    StateMistake("lift_sign", "SHADOW_LIFT has the wrong sign: the shadow is pushed below the floor and the depth test "
                 "hides it; lift it along the floor's normal, towards the light (+0.005)",
                 5, lambda t: dataclasses.replace(t, shadow_lift=-abs(t.shadow_lift) or -0.005)),
)


#: How alike two leak maps must be for a known mistake's hint: the share of the pixels leaking
#: in either that are in the same class in both.
ALIKE = 0.8


def alike(a: LeakMap, b: LeakMap) -> float:
    """The share of the pixels leaking in ``a`` or ``b`` that have the same class in both (1: equal maps)."""
    either = (a.classes != 0) | (b.classes != 0)
    total = int(np.count_nonzero(either))
    return 1.0 if total == 0 else int(np.count_nonzero(either & (a.classes == b.classes))) / total


def hints(leaks: LeakMap, mistake_maps: dict[str, LeakMap]) -> list[str]:
    """The hints of the known mistakes whose leak maps look like ``leaks`` (:data:`ALIKE`), most
    alike first; where none does, the hint of each mistake whose class ``leaks`` shows."""
    if leaks.empty:
        return []
    by_name = {m.name: m for m in MISTAKES}
    scored = sorted(((alike(leaks, lm), name) for name, lm in mistake_maps.items()), reverse=True)
    matched = [by_name[name] for score, name in scored if score >= ALIKE]
    if not matched:
        matched = [m for m in MISTAKES if np.any(leaks.classes == m.shows_as)]
    return [f"{m.name}: {m.hint}" for m in matched]


def mistake_maps(renderer: Any, reference: Capture) -> dict[str, LeakMap]:
    """Each known mistake's leak map (the tutorials' tables with that one mistake)."""
    tables = reference_tables()
    return {m.name: leak_map(reference, render_with(renderer, m.change(tables))) for m in MISTAKES}


@dataclass
class StateCheck:
    """A graded file: its leak map, the known mistakes' maps and the hints."""

    leaks: LeakMap
    hints: list[str]

    @property
    def passed(self) -> bool:
        return self.leaks.empty


def check_tables(renderer: Any, tables: StateTables) -> StateCheck:
    """``tables`` graded against the plan's own states on ``renderer``."""
    reference = render_with(renderer, None)
    leaks = leak_map(reference, render_with(renderer, tables))
    return StateCheck(leaks, hints(leaks, mistake_maps(renderer, reference)) if not leaks.empty else [])


def report(result: StateCheck, picture: Path | None) -> str:
    """What ``glsandbox exercise check mirror_states`` prints: the counts, the hints, the picture."""
    lines = ["mirror_states: the mirror room drawn with your state tables, against the tutorials' "
             f"({SIZE[0]}x{SIZE[1]}, lesson mirror {' '.join(SETTINGS)})"]
    for name, count in result.leaks.counts().items():
        lines.append(f"  {name:<36} {count:>6} pixels")
    lines.append("PASS: no pixel leaks" if result.passed else "FAIL: the leak map is not empty")
    lines += [f"hint: {h}" for h in result.hints]
    if picture is not None:
        lines.append(f"leak map: {picture}")
    return "\n".join(lines)


def write_picture(leaks: LeakMap, folder: Path) -> Path:
    """The leak map as ``folder/leak_map.png`` (the folder made if needed)."""
    from glsandbox.files import save_png

    folder.mkdir(parents=True, exist_ok=True)
    return save_png(leaks.picture(), folder / "leak_map.png")
