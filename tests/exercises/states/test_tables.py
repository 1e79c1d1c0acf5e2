"""A state exercise's tables read as data (glsandbox/exercises/states/tables.py): a file that is not
the tables is one error naming its line, and the file is never run."""

from __future__ import annotations

import pytest

from glsandbox.errors import SandboxError
from glsandbox.exercises.states.mirror import REFERENCE_SOURCE, starter
from glsandbox.exercises.states.tables import parse_tables


@pytest.mark.parametrize("change,fragments", [
    (lambda s: s + "\nimport os\n", ("f.py:61:", "only assignments")),
    (lambda s: s + "\nSHADOW_LIFT = __import__('os').getcwd()\n", ("f.py:61:", "literal")),
    (lambda s: s.replace('"D3D11_COMPARISON_EQUAL",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP"',
                         '"GL_EQUAL",\n    "StencilPassOp": "D3D11_STENCIL_OP_KEEP"'), ("f.py:", "'GL_EQUAL'")),
    (lambda s: s.replace('    "StencilRef": 1,\n}\n\n# CullClockwise', '}\n\n# CullClockwise'), ("lacks 'StencilRef'",)),
    (lambda s: s.replace("MARK_MIRROR_DSS =", "MARK_DSS ="), ("f.py:10:", "MARK_DSS is not one of the tables")),
    (lambda s: s.replace("SHADOW_LIFT = 0.005", "SHADOW_LIFT = True"), ("f.py:59:", "SHADOW_LIFT")),
    (lambda s: s + "\nx = (\n", ("f.py:", "not Python")),
    (lambda s: starter(), ("f.py:10:", "left blank")),
])
def test_a_file_that_is_not_the_tables_is_one_error_naming_the_line(change, fragments) -> None:
    with pytest.raises(SandboxError) as caught:
        parse_tables(change(REFERENCE_SOURCE), "f.py")
    message = str(caught.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, message
