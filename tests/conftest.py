"""Shared pytest fixtures and options, one section per topic."""

from __future__ import annotations

import gc
import os
import py_compile
import shutil
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from support import GOLDENS_DIR, RESULTS_DIR, TESTS_DIR, backend_available, need

from glsandbox.measure.golden import ImageMatch, check_golden


# --- golden images ---------------------------------------------------------
# The rule is glsandbox.measure.golden's (docs/testing.md).
# A lesson's goldens live in tests/goldens/<lesson>/<variant>.png (support.GOLDENS_DIR),
# failure artefacts go to the ignored test-results/ folder.

UPDATE_GOLDENS = "--update-goldens"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        UPDATE_GOLDENS,
        action="store_true",
        default=False,
        help=(
            "write missing golden images and rewrite failing ones under tests/goldens/; "
            "passing goldens are left untouched. Refused when CI is set."
        ),
    )


def pytest_configure(config: pytest.Config) -> None:
    if config.getoption(UPDATE_GOLDENS) and os.environ.get("CI"):
        raise pytest.UsageError(
            f"{UPDATE_GOLDENS} is refused while CI is set: goldens are never rewritten on CI"
        )


GoldenCheck = Callable[..., ImageMatch]


@pytest.fixture
def golden(request: pytest.FixtureRequest) -> GoldenCheck:
    """``golden(image, name, **tolerances)``: check ``image`` against tests/goldens/<name>.png.

    ``tolerances`` are ``threshold`` and ``max_bad_share`` (see
    :func:`glsandbox.measure.golden.compare_images`). ``name`` may contain ``/`` to
    group goldens in folders.
    """
    update = bool(request.config.getoption(UPDATE_GOLDENS))

    def check(image: np.ndarray, name: str, **tolerances: Any) -> ImageMatch:
        return check_golden(
            image,
            GOLDENS_DIR / f"{name}.png",
            update=update,
            results_dir=RESULTS_DIR,
            name=name,
            **tolerances,
        )

    return check


# --- bytecode for subprocesses ----------------------------------------------------
# Where bytecode writing is off (PYTHONDONTWRITEBYTECODE=1) and nothing compiled the
# installed packages (`uv sync --compile-bytecode`, docs/testing.md), every `glsandbox`
# subprocess compiles numpy, moderngl, Pillow and glsandbox again (`glsandbox
# render` started in 0.63 s instead of 0.23 s on a quiet machine). The modules this process
# imported while collecting (the same ones) are compiled once here, and again only when
# their source is newer.


def pytest_collection_finish(session: pytest.Session) -> None:
    if sys.dont_write_bytecode:
        compile_imported_modules()


def compile_imported_modules() -> None:
    for module in list(sys.modules.values()):
        source, cached = getattr(module, "__file__", None), getattr(module, "__cached__", None)
        if not (source and cached and source.endswith(".py")) or source.startswith(str(TESTS_DIR)):
            continue  # test modules: pytest rewrites and caches them itself
        try:
            if os.path.exists(cached) and os.stat(cached).st_mtime >= os.stat(source).st_mtime:
                continue
            py_compile.compile(source, cfile=cached, doraise=True)
        except (OSError, py_compile.PyCompileError):
            continue  # a read-only install or an odd file: that module is compiled at import, as before


# --- the garbage collector during collection -----------------------------------------
# Collecting ~2,500 tests rewrites the asserts of ~300 modules (pytest's assertion rewriting
# builds and compiles large syntax trees): the collector's automatic passes over those young
# objects, all of them alive until the module is compiled, are a quarter of collection's CPU
# (9.6 s against 7.0 s in one run, docs/testing.md). It is off while collecting; then one pass
# frees what collection left, and what is still alive (modules, test items, fixtures' functions,
# pytest's own state, alive to the end) is frozen out of every later pass: a full collection
# in a test (load_model runs one to free trimesh's reference cycles) then walks only what the
# tests made, not the whole session's heap.


@pytest.hookimpl(wrapper=True)
def pytest_collection(session: pytest.Session):
    gc.disable()
    try:
        return (yield)
    finally:
        gc.enable()
        gc.collect()
        gc.freeze()


# --- GL backends and displays ------------------------------------------------
# Tests that need a GL backend or an X server skip locally when it is missing,
# and fail when CI is set: on CI a missing backend is a broken set-up, never a
# reason to pass.


@pytest.fixture(scope="session")
def gl_renderer():
    """A headless renderer on the default backend (EGL, else OSMesa), shared by the session."""
    from glsandbox.frame import HeadlessRenderer
    from glsandbox.errors import SandboxError

    try:
        renderer = HeadlessRenderer()
    except SandboxError as exc:
        need("headless OpenGL", str(exc))
    yield renderer
    renderer.close()


@pytest.fixture
def gl(gl_renderer):
    """The shared :class:`~glsandbox.frame.HeadlessRenderer` (``gl.render(lesson, size)``), its
    context current: a command run in this process (support.run_cli) opens and closes a context
    of its own and leaves that one current, and ``gl.host.ctx`` used directly must not see it.

    Each test leaves the context's pipeline state as it found it (the state every frame and the
    gpu ray engine start from): what a test, or the code it drives, leaves set would change
    what later tests draw, and which test follows which depends on the order (``-n`` workers)."""
    host = gl_renderer.host
    host.make_current()
    before = shared_state(host)
    yield gl_renderer
    host.make_current()
    after = shared_state(host)
    changed = {key: (before[key], after[key]) for key in before if before[key] != after[key]}
    assert not changed, f"the test left GL state changed on the shared context (before, after): {changed}"


def shared_state(host) -> dict[str, object]:
    """What of a context's state one user can leave to the next: the pipeline switches
    (:meth:`~glsandbox.gl.rawgl.RawGL.state_snapshot`) and the sampler objects on units 0-3.
    Not the colour and depth write masks: moderngl sets a framebuffer's own at each ``use()``
    and ``clear()``, so nobody starts from the ones left (a frame leaves alpha off, its rule;
    the gpu ray engine's target has no depth, so its ``use()`` turns depth writes off)."""
    state = host.raw.state_snapshot()
    del state["color_writemask"], state["depth_writemask"]
    state["samplers"] = host.raw.sampler_bindings()
    return state


@pytest.fixture(scope="session")
def xvfb_display():
    """A private Xvfb server for window tests; yields its DISPLAY (e.g. ':5')."""
    import subprocess

    if shutil.which("Xvfb") is None:
        need("Xvfb", "the Xvfb binary is not installed (apt-get install xvfb)")
    # -noreset: by default Xvfb resets itself when its last client disconnects,
    # and a window opened during that reset fails with "Failed to open display"
    # (CI saw this between two window tests).
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "800x600x24", "-nolisten", "tcp",
                             "-noreset"],
                            pass_fds=(write_fd,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    with os.fdopen(read_fd) as pipe:
        number = pipe.readline().strip()
    if not number:
        proc.kill()
        need("Xvfb", "the server did not start")
    yield f":{number}"
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture
def window_env(xvfb_display: str) -> str:
    """The DISPLAY of the test X server, with xdotool to drive windows on it (support.LessonWindow)."""
    if shutil.which("xdotool") is None:
        need("xdotool", "not installed (apt-get install xdotool)")
    return xvfb_display


# --- headless backends and ray engines -----------------------------------------


@pytest.fixture(scope="session", params=["egl", "osmesa"])
def backend(request: pytest.FixtureRequest) -> str:
    """Each headless backend by name (``--backend NAME``), skipped (failed on CI) where it does not start."""
    reason = backend_available(request.param)
    if reason:
        need(f"the {request.param} backend", reason)
    return request.param


@dataclass(frozen=True)
class Engine:
    """A ray engine bound to what it needs: ``engine.render(scene, size, **options)``."""

    name: str
    ctx: Any = None

    def render(self, scene, size: tuple[int, int], **options: Any) -> np.ndarray:
        from glsandbox.raytrace import render

        return render(scene, size, self.name, ctx=self.ctx, **options)


@pytest.fixture(params=["numpy", "gpu"])
def engine(request: pytest.FixtureRequest) -> Engine:
    """Each ray engine: numpy (float64), and gpu (GLSL, float32) on the shared GL context."""
    if request.param == "gpu":
        return Engine("gpu", request.getfixturevalue("gl").host.ctx)
    return Engine("numpy")


# --- a browser ---------------------------------------------------------------


@pytest.fixture(scope="session")
def chromium() -> str:
    """The path of a headless-capable Chromium (Debian's ``chromium`` package; .ci/run installs it)."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    need("Chromium", "no chromium binary on PATH (apt-get install chromium)")
    raise AssertionError("unreachable")  # need() skips or fails
