"""The ``measure`` extra (glsandbox/measure/extra.py): a missing package is one ``error:`` line,
flip-evaluator alone may be missing, and matplotlib is checked before any work."""

from __future__ import annotations

import importlib

import pytest

from glsandbox.errors import SandboxError
from glsandbox.measure import extra


def _without(monkeypatch, *missing: str) -> list[str]:
    """Make the named modules fail to import; return the names imported."""
    asked: list[str] = []
    real = importlib.import_module

    def fake(name: str, *args, **kwargs):
        asked.append(name)
        if name.split(".")[0] in missing:
            raise ImportError(f"No module named {name!r}")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(extra.importlib, "import_module", fake)
    return asked


def test_require_returns_the_module_or_says_how_to_install_it(monkeypatch) -> None:
    assert extra.require("math") is importlib.import_module("math")
    _without(monkeypatch, "matplotlib")
    with pytest.raises(SandboxError) as caught:
        extra.require("matplotlib.pyplot")
    assert str(caught.value) == extra.MISSING and "uv run --extra measure" in extra.MISSING
    assert caught.value.__cause__ is None and caught.value.__suppress_context__  # no traceback chained


def test_has_flip_says_whether_flip_evaluator_imports(monkeypatch) -> None:
    asked = _without(monkeypatch, "flip_evaluator")
    assert extra.has_flip() is False and asked == ["flip_evaluator"]
    monkeypatch.undo()
    _without(monkeypatch)
    monkeypatch.setattr(extra.importlib, "import_module", lambda name: object())
    assert extra.has_flip() is True


def test_require_all_needs_matplotlib_but_not_flip(monkeypatch) -> None:
    asked = _without(monkeypatch, "flip_evaluator", "matplotlib")
    with pytest.raises(SandboxError, match="needs matplotlib"):
        extra.require_all()
    assert asked == ["matplotlib"]
    monkeypatch.undo()
    asked = _without(monkeypatch, "flip_evaluator")
    monkeypatch.setattr(extra.importlib, "import_module", lambda name: asked.append(name))
    extra.require_all()  # flip-evaluator missing is not an error here
    assert asked == ["matplotlib"] and set(extra.MODULES) == {"flip_evaluator", "matplotlib"}
