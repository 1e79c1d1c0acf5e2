"""The file a student starts from: the signature, the docstring, the worked example.

``glsandbox exercise start NAME`` writes it. Its body raises
``NotImplementedError``, so a starter never passes a case.
"""

from __future__ import annotations

from glsandbox.exercises.definition import Exercise

__all__ = ["starter"]


def starter(exercise: Exercise) -> str:
    """The starter file's text for ``exercise``."""
    doc = exercise.doc.strip().replace('"""', "'''")
    body = "\n".join(f"    {line}".rstrip() for line in doc.splitlines())
    convention = f"\n# Convention: {exercise.convention}\n" if exercise.convention else ""
    return (f'"""Exercise {exercise.name}: {exercise.summary}.\n\n'
            f"Check it with:  glsandbox exercise check {exercise.name} THIS_FILE.py\n"
            f'"""\n{convention}\n\n'
            f"def {exercise.signature}:\n"
            f'    """{body.lstrip()}\n    """\n'
            f"    # The worked example, which your function must reproduce:\n"
            f"    #   {exercise.example}\n"
            f'    raise NotImplementedError("write {exercise.function}")\n')
