"""The package's layers: imports point down only, with no loop, and lessons use the public face.

Every import is read from the source (top-level, inside functions and under
``TYPE_CHECKING`` alike), so an import hidden in a function cannot hide a loop.
The table is the one in docs/how-it-works.md.
"""

from __future__ import annotations

import ast
import functools
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Lowest first. A module may import its own layer and the ones above it in this list.
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("core", ("glsandbox.errors", "glsandbox.transforms", "glsandbox.mesh.normals", "glsandbox.mesh.looks",
              "glsandbox.mesh.precheck", "glsandbox.geometry", "glsandbox.mesh.generate", "glsandbox.files",
              "glsandbox.progress", "glsandbox.version", "glsandbox.course_lessons")),
    # glsandbox.mesh: its package and the model-file loader here, the rest of it in the core
    ("scene data", ("glsandbox.scene", "glsandbox.planar", "glsandbox.images",
                    "glsandbox.overlay", "glsandbox.mesh")),
    ("scene logic", ("glsandbox.scene_file", "glsandbox.shadowmap", "glsandbox.passes", "glsandbox.plan_variants",
                     "glsandbox.plan_notes", "glsandbox.plan", "glsandbox.camera", "glsandbox.lesson")),
    ("renderers", ("glsandbox.gl", "glsandbox.raytrace")),
    ("one frame", ("glsandbox.frame",)),
    ("app and measuring", ("glsandbox.app", "glsandbox.course_page", "glsandbox.lesson_pages", "glsandbox.measure",
                           # an exercise's data, its catalogue and its pictures (the course page lists them)
                           "glsandbox.exercises.definition", "glsandbox.exercises.fields", "glsandbox.exercises.compare",
                           "glsandbox.exercises.plain",
                           "glsandbox.exercises.catalogue", "glsandbox.exercises.probe",
                           "glsandbox.exercises.lesson_view", "glsandbox.exercises.student_process",
                           "glsandbox.exercises.dxmath", "glsandbox.story")),
    ("grading", ("glsandbox.grading", "glsandbox.exercises")),
    ("command line", ("glsandbox.cli", "glsandbox.supervise", "glsandbox.interrupt_watch", "glsandbox.pytest_plugin",
                      "glsandbox.__main__", "glsandbox.launch")),
]

#: The two doors up, each opened only when called: lesson discovery
#: (``glsandbox.lesson`` imports the course's lessons, ``glsandbox.lessons``: the repository's
#: ``lessons/`` folder) and ``glsandbox.run``
#: (the public face imports the command line).
ALLOWED_UP = {("glsandbox.lesson", "glsandbox.lessons"), ("glsandbox", "glsandbox.cli")}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def is_module(name: str) -> bool:
    base = ROOT.joinpath(*name.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def import_statements(path: Path) -> list[tuple[str, list[str]]]:
    """(module as written, names imported from it) for every import in ``path``, nested ones too."""
    found: list[tuple[str, list[str]]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.extend((a.name, []) for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.append((node.module, [a.name for a in node.names]))
    return [(module, names) for module, names in found if module.split(".")[0] in ("glsandbox", "lessons")]


def imports_of(path: Path) -> set[str]:
    """Every glsandbox/lessons module ``path`` imports, resolved to module names
    (``from glsandbox import geometry`` imports the module ``glsandbox.geometry``)."""
    resolved: set[str] = set()
    for module, names in import_statements(path):
        resolved.update({f"{module}.{n}" if is_module(f"{module}.{n}") else module for n in names} or {module})
    return resolved


def layer_of(name: str) -> int | None:
    for index, (_, prefixes) in enumerate(LAYERS):
        if any(name == p or name.startswith(p + ".") for p in prefixes):
            return index
    return None


@functools.cache
def graph() -> dict[str, frozenset[str]]:
    """Each module's imports, parsed once for the file's tests (about 0.5 s of CPU a parse)."""
    files = [*ROOT.glob("glsandbox/**/*.py"), *ROOT.glob("lessons/*.py")]
    return {module_name(f): frozenset(imports_of(f)) for f in files}


def test_every_package_module_has_a_layer():
    unplaced = [m for m in graph() if m.startswith("glsandbox.") and layer_of(m) is None]
    assert not unplaced, f"modules missing from the layer table (docs/how-it-works.md and LAYERS): {unplaced}"


#: Folders whose modules are entries of one registry, each named after its entry (a pass kind on
#: both sides, a ray-traced shape, a knob, an exercise): their names may be others' too.
REGISTRY_FOLDERS = ("glsandbox.passes.", "glsandbox.gl.passes.", "glsandbox.raytrace.shapes.",
                    "glsandbox.measure.knobs.", "glsandbox.exercises.catalogue.")


def registry_entry(module: str) -> bool:
    """A module named after its registry's entry. Of the pass folders only the kinds
    (``glsandbox.passes.PASS_KINDS``): the plan's parts and the order string beside them are named
    for their jobs like any module."""
    from glsandbox.passes import PASS_KINDS

    if not (module + ".").startswith(REGISTRY_FOLDERS):
        return False
    if module.startswith(("glsandbox.passes.", "glsandbox.gl.passes.")):
        return module.rsplit(".", 1)[1] in PASS_KINDS
    return True


def test_no_module_name_is_used_in_two_layers():
    """A name says one job: the GL side of a scene-data module is named for what it does with it
    (``planar`` and ``gl.planar_state``), not after the data again."""
    by_name: dict[str, set[int]] = {}
    for module in graph():
        if not module.startswith("glsandbox.") or registry_entry(module) or module + "." in REGISTRY_FOLDERS:
            continue  # (the registries' own packages too: passes and gl.passes are one pair)
        layer = layer_of(module)
        if layer is not None:
            by_name.setdefault(module.rsplit(".", 1)[1], set()).add(layer)
    shared = sorted(name for name, layers in by_name.items() if len(layers) > 1)
    assert shared == [], f"module names used in two layers (rename one for its job): {shared}"


def test_imports_point_down_only():
    upward = []
    for module, targets in graph().items():
        if not module.startswith("glsandbox"):
            continue
        for target in targets:
            if (module, target) in ALLOWED_UP or target == module:
                continue
            if target == "glsandbox" and module != "glsandbox":
                upward.append(f"{module} -> the public face (import the module that defines the name)")
                continue
            here, there = layer_of(module), layer_of(target)
            if module == "glsandbox" or there is None:
                continue
            if here is None or there > here or target.startswith("lessons"):
                upward.append(f"{module} ({LAYERS[here][0] if here is not None else '?'}) -> "
                              f"{target} ({LAYERS[there][0]})")
    assert not upward, "imports pointing up:\n" + "\n".join(sorted(upward))


def test_the_rasterizer_never_imports_the_ray_tracer():
    offenders = [f"{m} -> {t}" for m, ts in graph().items() if m.startswith("glsandbox.gl")
                 for t in ts if t.startswith("glsandbox.raytrace")]
    assert not offenders


def test_no_import_loop():
    full = graph()
    edges = {m: {t for t in ts if t in full} for m, ts in full.items()}
    edges.pop("glsandbox", None)  # the public face re-exports; nothing inside imports it (tested above)
    for targets in edges.values():
        targets.discard("glsandbox")
    state: dict[str, int] = {}
    stack: list[str] = []
    loops: list[list[str]] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                loops.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            visit(node)
    assert not loops, "import loops: " + "; ".join(" -> ".join(loop) for loop in loops)


def test_lessons_use_only_the_public_face():
    allowed = {"glsandbox", "glsandbox.raytrace"}
    reaching = {}
    for path in ROOT.glob("lessons/*.py"):
        bad = sorted(t for t in {module for module, _ in import_statements(path)} - allowed if not t.startswith("lessons._"))
        if bad:
            reaching[path.name] = bad
    assert not reaching, f"lessons reaching past glsandbox and glsandbox.raytrace: {reaching}"


def test_public_face_has_what_a_lesson_needs():
    import glsandbox

    for name in ("Scene", "Node", "Material", "Camera", "Light", "Viewport", "Texture", "Mirror",
                 "PlanarShadow", "Overlay", "Lesson", "Param", "register", "geometry", "transforms", "run"):
        assert hasattr(glsandbox, name), name
    assert set(glsandbox.__all__) <= set(dir(glsandbox))


def test_a_raster_frame_never_loads_the_ray_tracer_and_import_glsandbox_loads_no_gl():
    script = textwrap.dedent("""
        import sys
        import glsandbox
        assert not any(m.startswith(("moderngl", "glsandbox.gl", "glsandbox.cli")) for m in sys.modules), \\
            sorted(m for m in sys.modules if m.startswith("glsandbox"))
        from glsandbox import Node, Scene, geometry
        from glsandbox.frame import HeadlessRenderer
        try:
            renderer = HeadlessRenderer()
        except glsandbox.SandboxError as exc:
            print("no-gl", exc)
            raise SystemExit(0)
        with renderer:
            renderer.render_scene(Scene("cube", nodes=(Node("cube", geometry.cube()),)), (32, 32))
        loaded = sorted(m for m in sys.modules if m.startswith("glsandbox.raytrace"))
        assert not loaded, loaded
        print("ok")
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    if result.stdout.startswith("no-gl"):
        from support import need

        need("a GL backend", result.stdout)
    assert result.stdout.strip() == "ok"
