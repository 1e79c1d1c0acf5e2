"""A pytest plugin for your own repository: golden images of your own scenes and lessons.

Installed with glsandbox (the ``pytest11`` entry point), it adds the fixture
``glsandbox_golden``::

    def test_my_lesson(glsandbox_golden):
        glsandbox_golden("my_lesson.py", "my_lesson", settings=["time=1"])  # or settings={"time": 1}

which renders the subject headless and checks it against
``goldens/<name>.png`` beside the test file with the project's golden rule
(:func:`glsandbox.measure.golden.check_golden`). The subject is a lesson name,
a ``.py`` lesson file or a ``.toml`` scene file (a relative path is taken
from the test file's folder), a ``.png`` file, a Lesson class or instance, a
:class:`~glsandbox.scene.Scene`, or an RGBA image array.

* ``pytest --glsandbox-update`` writes missing goldens and rewrites failing
  ones (passing ones are kept); it is refused when ``CI`` is set.
* A failure writes ``<name>-actual.png``, ``-expected.png`` and ``-diff.png``
  into ``test-results/`` under pytest's root folder.
* The ini option ``glsandbox_goldens`` puts every golden in one folder
  (relative to the root folder) instead.

Nothing here opens a GL context until a check renders; one context is
shared by the session.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import pytest

UPDATE_FLAG = "--glsandbox-update"
GOLDENS_INI = "glsandbox_goldens"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(UPDATE_FLAG, action="store_true", default=False,
                     help="glsandbox_golden: write missing goldens and rewrite failing ones (refused when CI is set)")
    parser.addini(GOLDENS_INI, default="",
                  help="glsandbox_golden: one folder for every golden, relative to the root folder "
                       "(default: goldens/ beside each test file)")


def pytest_configure(config: pytest.Config) -> None:
    if config.getoption(UPDATE_FLAG) and os.environ.get("CI"):
        raise pytest.UsageError(f"{UPDATE_FLAG} is refused while CI is set: goldens are never rewritten on CI")


@pytest.fixture(scope="session")
def glsandbox_renderer() -> Iterator[Any]:
    """A headless renderer opened on first use and shared by the session."""
    from glsandbox.frame import LazyRenderer

    lazy = LazyRenderer()
    yield lazy
    lazy.close()


@pytest.fixture
def glsandbox_golden(request: pytest.FixtureRequest, glsandbox_renderer: Any) -> Callable[..., Any]:
    """``glsandbox_golden(subject, name, settings=(), size=None, samples=0, threshold=2, max_bad_share=0.0005)``.

    ``settings`` is a list of ``"key=value"`` texts (as ``--set`` takes them)
    or a dict ``{"time": 1.0, "shading": "phong"}``. A mistake in the call (an
    unknown setting, a threshold that is not a number, a golden that is a
    folder, a lesson that does not load) fails the test with one line.

    Renders ``subject`` (see the module's docstring), checks it against
    ``<goldens>/<name>.png`` and returns the :class:`~glsandbox.measure.golden.ImageMatch`;
    a mismatch or a missing golden fails the test with the figures and the
    way to update. ``size`` is ``(W, H)`` or ``"WxH"``; by default the
    golden's own size (640x480 when there is none yet).
    """
    from glsandbox.measure.golden import check_golden

    update = bool(request.config.getoption(UPDATE_FLAG))
    configured = request.config.getini(GOLDENS_INI)
    root = Path(request.config.rootpath)
    here = Path(request.path).parent
    goldens = (root / configured) if configured else here / "goldens"

    def check(subject: Any, name: str, *, settings: Any = (), size: Any = None, samples: int = 0,
              **tolerances: Any) -> Any:
        from glsandbox.errors import SandboxError

        try:
            golden = _golden_path(goldens, name)
            texts = _settings(settings)
            checked = _tolerances(tolerances)
            frame_size = _size(size, golden)
            image = _image_of(subject, here, texts, frame_size, _samples(samples), glsandbox_renderer)
        except SandboxError as exc:
            mistake = str(exc)
        else:
            return check_golden(image, golden, update=update, results_dir=root / "test-results", name=name,
                                hint=f"run pytest {UPDATE_FLAG}", **checked)
        # A mistake in the call (or the lesson): one line, not a traceback from inside glsandbox.
        pytest.fail(f"glsandbox_golden: {mistake}", pytrace=False)

    return check


def _golden_path(goldens: Path, name: Any) -> Path:
    """``<goldens>/<name>.png``; a name that leaves the folder, or a golden that is a folder, is refused."""
    from glsandbox.errors import SandboxError, plain

    if not isinstance(name, str) or not name.strip() or Path(name).is_absolute() or ".." in Path(name).parts:
        raise SandboxError(f"name must be a relative name without '..' (the golden's file stem), got {plain(name)}")
    golden = goldens / f"{name}.png"
    if golden.is_dir():  # also under --glsandbox-update: a folder is never replaced by an image
        raise SandboxError(f"golden {golden} is a folder, not a .png file; move it away or pick another name")
    return golden


def _settings(settings: Any) -> list[str]:
    """``settings`` as ``--set`` texts: a list or tuple of ``"key=value"`` texts, one such text,
    or a dict ``{"key": value}`` (on/off for bools, commas between the numbers of a list)."""
    from collections.abc import Mapping

    from glsandbox.errors import SandboxError, plain

    if settings is None:
        return []
    if isinstance(settings, str):
        return [settings]
    if isinstance(settings, Mapping):
        def text(value: Any) -> str:
            if isinstance(value, bool):
                return "on" if value else "off"
            if isinstance(value, (list, tuple)):
                return ",".join(str(v) for v in value)
            return str(value)

        return [f"{key}={text(value)}" for key, value in settings.items()]
    if isinstance(settings, (list, tuple)) and all(isinstance(item, str) for item in settings):
        return list(settings)
    raise SandboxError('settings must be a list of "key=value" texts or a dict {"key": value}, '
                       f"got {plain(settings)}")


def _tolerances(tolerances: dict[str, Any]) -> dict[str, Any]:
    """``threshold`` (0..255 levels) and ``max_bad_share`` (0..1), checked; nothing else is taken."""
    from glsandbox.errors import SandboxError, check_number

    unknown = sorted(set(tolerances) - {"threshold", "max_bad_share"})
    if unknown:
        raise SandboxError(f"unknown argument {unknown[0]!r}; the tolerances are threshold and max_bad_share")
    checked = {}
    if "threshold" in tolerances:
        value = check_number(tolerances["threshold"], "threshold", 0, 255)
        if value != int(value):
            raise SandboxError(f"threshold must be a whole number of levels (0..255), got {value:g}")
        checked["threshold"] = int(value)
    if "max_bad_share" in tolerances:
        checked["max_bad_share"] = check_number(tolerances["max_bad_share"], "max_bad_share", 0.0, 1.0)
    return checked


def _samples(samples: Any) -> int:
    from glsandbox.errors import SandboxError, plain

    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 0:
        raise SandboxError(f"samples must be a whole number >= 0, got {plain(samples)}")
    return samples


def _size(size: Any, golden: Path) -> tuple[int, int]:
    from glsandbox.cli import parse_size
    from glsandbox.errors import SandboxError, plain
    from glsandbox.frame import DEFAULT_SIZE
    from glsandbox.files import load_png

    if isinstance(size, str):
        return parse_size(size)
    if size is not None:
        if isinstance(size, (list, tuple)) and len(size) == 2 \
                and all(isinstance(v, int) and not isinstance(v, bool) for v in size):
            return parse_size(f"{size[0]}x{size[1]}")
        raise SandboxError(f'size must be (width, height) or "WxH", got {plain(size)}')
    try:
        height, width = load_png(golden).shape[:2]
    except OSError:  # none yet, or unreadable: check_golden reports it
        return DEFAULT_SIZE
    return width, height


def _image_of(subject: Any, here: Path, settings: Sequence[str], size: tuple[int, int], samples: int,
              lazy: Any) -> Any:
    """The RGBA image a subject stands for, rendered on the shared context when it is a scene or lesson."""
    import numpy as np

    from glsandbox.errors import SandboxError
    from glsandbox.files import load_png
    from glsandbox.frame import with_samples
    from glsandbox.lesson import Lesson, find_lesson
    from glsandbox.scene import Scene

    if isinstance(subject, np.ndarray):
        return subject
    if isinstance(subject, Scene):
        return lazy.renderer.render_scene(with_samples(subject, samples), size).image
    if isinstance(subject, (str, os.PathLike)):
        text = os.fspath(subject)
        path = Path(text)
        if not path.is_absolute() and (here / path).exists():
            text = str(here / path)
        if text.endswith(".png"):
            return load_png(text)
        subject = find_lesson(text)
    if isinstance(subject, type) and issubclass(subject, Lesson):
        subject = subject.from_settings(settings)
    elif settings:
        raise SandboxError("settings= applies to a lesson given by name, file or class")
    if isinstance(subject, Lesson):
        return lazy.renderer.render(subject, size, samples).image
    raise SandboxError(f"cannot check a {type(subject).__name__}; give a lesson name or file, "
                       "a .png, a Lesson, a Scene or an RGBA image array")
