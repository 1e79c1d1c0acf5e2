"""A pytest plugin for your own repository: golden images of your own scenes and lessons.

Installed with glsandbox (the ``pytest11`` entry point), it adds the fixture
``glsandbox_golden``::

    def test_my_lesson(glsandbox_golden):
        glsandbox_golden("my_lesson.py", "my_lesson", settings=["time=1"])

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

    def check(subject: Any, name: str, *, settings: Sequence[str] = (), size: Any = None, samples: int = 0,
              **tolerances: Any) -> Any:
        golden = goldens / f"{name}.png"
        image = _image_of(subject, here, settings, _size(size, golden), samples, glsandbox_renderer)
        return check_golden(image, golden, update=update, results_dir=root / "test-results", name=name,
                            hint=f"run pytest {UPDATE_FLAG}", **tolerances)

    return check


def _size(size: Any, golden: Path) -> tuple[int, int]:
    from glsandbox.cli import parse_size
    from glsandbox.frame import DEFAULT_SIZE
    from glsandbox.files import load_png

    if isinstance(size, str):
        return parse_size(size)
    if size is not None:
        return int(size[0]), int(size[1])
    try:
        height, width = load_png(golden).shape[:2]
    except OSError:  # none yet, or unreadable: check_golden reports it
        return DEFAULT_SIZE
    return width, height


def _image_of(subject: Any, here: Path, settings: Sequence[str], size: tuple[int, int], samples: int,
              lazy: Any) -> Any:
    """The RGBA image a subject stands for, rendered on the shared context when it is a scene or lesson."""
    import numpy as np

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
        raise TypeError("settings= applies to a lesson given by name, file or class")
    if isinstance(subject, Lesson):
        return lazy.renderer.render(subject, size, samples).image
    raise TypeError(f"glsandbox_golden: cannot check a {type(subject).__name__}; give a lesson name or file, "
                    "a .png, a Lesson, a Scene or an RGBA image array")
