"""Shared pytest fixtures and options, one section per topic."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from glsandbox.golden import Comparison, check_golden

REPO_ROOT = Path(__file__).resolve().parent.parent  # the folder with pyproject.toml


# --- golden images ---------------------------------------------------------
# See DESIGN.md, "Golden images". Goldens live in tests/goldens/<name>.png,
# failure artefacts go to the ignored test-results/ folder.

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


GoldenCheck = Callable[..., Comparison]


@pytest.fixture
def golden(request: pytest.FixtureRequest) -> GoldenCheck:
    """``golden(image, name, **tolerances)``: check ``image`` against tests/goldens/<name>.png.

    ``tolerances`` are ``threshold`` and ``max_bad_share`` (see
    :func:`glsandbox.golden.compare_images`). ``name`` may contain ``/`` to
    group goldens in folders.
    """
    update = bool(request.config.getoption(UPDATE_GOLDENS))

    def check(image: np.ndarray, name: str, **tolerances: Any) -> Comparison:
        return check_golden(
            image,
            GOLDENS_DIR / f"{name}.png",
            update=update,
            results_dir=RESULTS_DIR,
            name=name,
            **tolerances,
        )

    return check
