"""The pytest plugin users get with glsandbox (glsandbox_golden), run on a tiny user test suite via pytester."""

from __future__ import annotations

import numpy as np
import pytest

from glsandbox.files import load_png, save_png
from support import SPIN

pytest_plugins = ["pytester"]

USER_TESTS = '''
import numpy as np
from glsandbox import Node, Scene, geometry

def test_my_lesson(glsandbox_golden):
    match = glsandbox_golden("spin.py", "spin", settings=["time=0.5"], size=(64, 48))
    assert match.passed

def test_a_scene_and_an_image(glsandbox_golden):
    glsandbox_golden(Scene("one", nodes=(Node("cube", geometry.cube()),)), "scene", size="32x24")
    glsandbox_golden(np.full((8, 8, 4), 200, dtype=np.uint8), "flat")
'''


@pytest.fixture
def user_suite(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, gl) -> pytest.Pytester:
    monkeypatch.delenv("CI", raising=False)  # the user's own machine; CI is tested on its own below
    pytester.makepyfile(test_mine=USER_TESTS)
    (pytester.path / "spin.py").write_text(SPIN)
    return pytester


def test_missing_golden_update_then_pass_then_a_change_fails_with_images(user_suite: pytest.Pytester,
                                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    goldens = user_suite.path / "goldens"
    result = user_suite.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*missing golden*spin.png; run pytest --glsandbox-update*"])
    assert not goldens.exists()

    result = user_suite.runpytest("-p", "no:cacheprovider", "--glsandbox-update")
    result.assert_outcomes(passed=2)
    assert load_png(goldens / "spin.png").shape == (48, 64, 4)  # size=(64, 48)
    assert load_png(goldens / "scene.png").shape == (24, 32, 4)
    assert np.all(load_png(goldens / "flat.png") == 200)

    result = user_suite.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2)

    # the lesson changes: the check fails with the figures and leaves its images
    (user_suite.path / "spin.py").write_text(SPIN.replace("rotate_y(", "rotate_x(0.5) @ transforms.rotate_y("))
    before = (goldens / "spin.png").read_bytes()
    result = user_suite.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(["*golden mismatch for*spin.png*", "*FAIL: * bad of 3072 pixels*",
                                 "*if the change is intended, run pytest --glsandbox-update"])
    results = user_suite.path / "test-results"
    assert {p.name for p in results.iterdir()} == {"spin-actual.png", "spin-expected.png", "spin-diff.png"}
    assert (goldens / "spin.png").read_bytes() == before

    # under CI the update is refused before any test runs, and nothing is rewritten
    monkeypatch.setenv("CI", "true")
    result = user_suite.runpytest("-p", "no:cacheprovider", "--glsandbox-update")
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    result.stderr.fnmatch_lines(["*--glsandbox-update is refused while CI is set*"])
    assert (goldens / "spin.png").read_bytes() == before


def test_goldens_folder_from_the_ini_option(user_suite: pytest.Pytester) -> None:
    user_suite.makeini("[pytest]\nglsandbox_goldens = refs/images\n")
    save_png(np.zeros((8, 8, 4), dtype=np.uint8), user_suite.path / "refs" / "images" / "flat.png")
    result = user_suite.runpytest("-p", "no:cacheprovider", "-k", "scene_and_an_image")
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*missing golden*refs/images/scene.png*"])  # found flat's folder, scene missing
    result = user_suite.runpytest("-p", "no:cacheprovider", "-k", "scene_and_an_image", "--glsandbox-update")
    result.assert_outcomes(passed=1)
    assert np.all(load_png(user_suite.path / "refs" / "images" / "flat.png") == 200)  # the failing one rewritten
    assert not (user_suite.path / "goldens").exists()


def test_the_plugin_is_registered_in_this_run(pytestconfig: pytest.Config) -> None:
    plugin = pytestconfig.pluginmanager.get_plugin("glsandbox")
    assert plugin is not None and plugin.__name__ == "glsandbox.pytest_plugin"
    assert pytestconfig.getoption("--glsandbox-update") is False
