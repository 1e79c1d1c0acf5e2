"""The file a student starts from (glsandbox/exercises/starter.py), for every exercise: Python that
defines the function with its signature and docstring, names the command that checks it and the
worked example, and raises NotImplementedError."""

from __future__ import annotations

import ast

import pytest

from glsandbox.exercises import all_exercises
from glsandbox.exercises.starter import starter


@pytest.mark.parametrize("exercise", all_exercises(), ids=lambda e: e.name)
def test_the_starter_defines_the_function_and_says_how_to_check_it(exercise) -> None:
    text = starter(exercise)
    tree = ast.parse(text)
    (function,) = [node for node in tree.body if isinstance(node, ast.FunctionDef)]
    assert function.name == exercise.function
    assert [a.arg for a in function.args.args] == list(exercise.params)
    assert ast.get_docstring(function).split()[:3] == exercise.doc.split()[:3]
    assert f"glsandbox exercise check {exercise.name} THIS_FILE.py" in ast.get_docstring(tree)
    assert f"#   {exercise.example}" in text
    namespace: dict = {}
    exec(compile(tree, "starter.py", "exec"), namespace)  # noqa: S102 - our own generated text
    with pytest.raises(NotImplementedError, match=f"write {exercise.function}"):
        namespace[exercise.function](*([None] * len(exercise.params)))
