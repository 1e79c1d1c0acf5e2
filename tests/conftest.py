"""Shared pytest fixtures and options, one section per topic."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from glsandbox.measure.golden import ImageMatch, check_golden

REPO_ROOT = Path(__file__).resolve().parent.parent  # the folder with pyproject.toml


# --- golden images ---------------------------------------------------------
# The rule is glsandbox.measure.golden's (README, "Tests and golden images").
# Goldens live in tests/goldens/<name>.png, failure artefacts go to the
# ignored test-results/ folder.

GOLDENS_DIR = REPO_ROOT / "tests" / "goldens"
RESULTS_DIR = REPO_ROOT / "test-results"
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


# --- GL backends and displays ------------------------------------------------
# Tests that need a GL backend or an X server skip locally when it is missing,
# and fail when CI is set: on CI a missing backend is a broken set-up, never a
# reason to pass.


def need(resource: str, reason: str) -> None:
    """Skip (locally) or fail (CI) because ``resource`` is unavailable."""
    message = f"{resource} unavailable: {reason}"
    if os.environ.get("CI"):
        pytest.fail(f"{message} (CI is set, so this fails instead of skipping)", pytrace=False)
    pytest.skip(message)


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
    """The shared :class:`~glsandbox.frame.HeadlessRenderer` (``gl.render(lesson, size)``)."""
    return gl_renderer


def backend_available(name: str) -> str | None:
    """None when the backend starts here, else the reason (in a subprocess,
    so a failed start cannot disturb this process's contexts)."""
    import subprocess
    import sys

    code = ("from glsandbox.gl.context import open_context; import sys; "
            f"h = open_context({name!r}); h.release()")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    return None if proc.returncode == 0 else (proc.stderr.strip().splitlines() or ["failed"])[-1]


@pytest.fixture(scope="session")
def xvfb_display():
    """A private Xvfb server for window tests; yields its DISPLAY (e.g. ':5')."""
    import shutil
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


# --- a browser ---------------------------------------------------------------


@pytest.fixture(scope="session")
def chromium() -> str:
    """The path of a headless-capable Chromium (Debian's ``chromium`` package; .ci/run installs it)."""
    import shutil

    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    need("Chromium", "no chromium binary on PATH (apt-get install chromium)")
    raise AssertionError("unreachable")  # need() skips or fails
