"""The pytest plugin's fixture takes what a user hands it with care.

``settings`` as a dict or a list works; a mistake in the call fails the test
with one line ``glsandbox_golden: ...`` (no traceback from inside glsandbox),
with and without ``--glsandbox-update``, and writes nothing.
"""

from __future__ import annotations

import pytest

pytest_plugins = ["pytester"]

LESSON = '''
from glsandbox import Lesson, Node, Param, Scene, Material, geometry


class Tint(Lesson):
    name = "tint"
    params = (Param("red", 0.5, "how red", minimum=0.0, maximum=1.0),
              Param("lit", False, "light it"))

    def build(self):
        shading = "phong" if self.values["lit"] else "solid"
        material = Material(color=(self.values["red"], 0.2, 0.2, 1.0), shading=shading)
        return Scene("tint", nodes=(Node("cube", geometry.cube24(), material=material),))
'''

SETTINGS = '''
def test_list(glsandbox_golden):
    assert glsandbox_golden("tint.py", "a", settings=["red=0.9", "lit=on"], size=(32, 24)).passed

def test_dict(glsandbox_golden):
    assert glsandbox_golden("tint.py", "a", settings={"red": 0.9, "lit": True}, size=(32, 24)).identical

def test_one_text(glsandbox_golden):
    assert glsandbox_golden("tint.py", "a", settings="red=0.9", size=(32, 24)).passed is False
'''


@pytest.fixture
def suite(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch, gl) -> pytest.Pytester:
    monkeypatch.delenv("CI", raising=False)
    (pytester.path / "tint.py").write_text(LESSON)
    return pytester


def files_in(folder) -> set:
    return {p.relative_to(folder) for p in folder.rglob("*") if "__pycache__" not in p.parts
            and ".pytest_cache" not in p.parts}


def test_settings_as_a_list_a_dict_or_one_text(suite: pytest.Pytester) -> None:
    suite.makepyfile(test_settings=SETTINGS)
    result = suite.runpytest("-p", "no:cacheprovider", "-k", "test_list", "--glsandbox-update")
    result.assert_outcomes(passed=1)
    # the dict renders the very same picture as the list; one text is one setting (lit stays off)
    result = suite.runpytest("-p", "no:cacheprovider", "-k", "test_dict or test_one_text")
    assert result.ret in (0, 1)
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(["*test_one_text*golden mismatch*"])


MISTAKES = {
    "threshold_text": ('glsandbox_golden("tint.py", "a", threshold="two")',
                       "glsandbox_golden: threshold must be a number, got 'two'"),
    "threshold_fraction": ('glsandbox_golden("tint.py", "a", threshold=2.5)',
                           "glsandbox_golden: threshold must be a whole number of levels (0..255), got 2.5"),
    "share_range": ('glsandbox_golden("tint.py", "a", max_bad_share=5)',
                    "glsandbox_golden: max_bad_share must lie within 0..1, got 5"),
    "unknown_tolerance": ('glsandbox_golden("tint.py", "a", tolerance=3)',
                          "glsandbox_golden: unknown argument 'tolerance'; the tolerances are threshold and *"),
    "settings_number": ('glsandbox_golden("tint.py", "a", settings=5)',
                        'glsandbox_golden: settings must be a list of "key=value" texts or a dict *, got 5'),
    "settings_unknown": ('glsandbox_golden("tint.py", "a", settings={"blue": 1})',
                         "glsandbox_golden: --set blue: tint has no parameter 'blue'*"),
    "settings_bad_value": ('glsandbox_golden("tint.py", "a", settings={"red": "lots"})',
                           "glsandbox_golden: --set red=lots: expected a number"),
    "name_escapes": ('glsandbox_golden("tint.py", "../a")',
                     "glsandbox_golden: name must be a relative name without '..'*"),
    "size_words": ('glsandbox_golden("tint.py", "a", size="big")',
                   "glsandbox_golden: --size 'big': expected WIDTHxHEIGHT*"),
    "subject_number": ('glsandbox_golden(42, "a")', "glsandbox_golden: cannot check a int; *"),
    "golden_folder": ('glsandbox_golden("tint.py", "folder")',
                      "glsandbox_golden: golden *goldens/folder.png is a folder, not a .png file*"),
    "lesson_mistake": ('glsandbox_golden("broken.py", "a")',
                       "glsandbox_golden: *broken.py:4: Broken.build() returned None (a forgotten return?)*"),
}


@pytest.mark.parametrize("update", [False, True], ids=["check", "update"])
def test_each_mistake_fails_with_one_line_and_writes_nothing(suite: pytest.Pytester, update: bool) -> None:
    suite.makepyfile(test_mistakes="\n".join(f"def test_{name}(glsandbox_golden):\n    {call}\n"
                                             for name, (call, _) in MISTAKES.items()))
    (suite.path / "goldens" / "folder.png").mkdir(parents=True)
    (suite.path / "broken.py").write_text("from glsandbox import Lesson\n\nclass Broken(Lesson):\n"
                                          "    def build(self):\n        pass\n")
    before = files_in(suite.path)
    result = suite.runpytest("-p", "no:cacheprovider", "-rf", *(["--glsandbox-update"] if update else []))
    result.assert_outcomes(failed=len(MISTAKES))
    for name, (_, line) in MISTAKES.items():  # each failure's whole report is its one line
        result.stdout.fnmatch_lines([f"_* test_{name} _*", line, "_* test_*"
                                     if name != list(MISTAKES)[-1] else "=* short test summary info =*"])
    output = result.stdout.str()
    assert "Traceback" not in output and "During handling" not in output and "glsandbox/" not in output
    assert files_in(suite.path) == before  # no golden written, no folder replaced, no artefacts
