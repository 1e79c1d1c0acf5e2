"""The warm template (glsandbox.grading.warm): renderers forked from a context already drawn with."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np

from glsandbox.lesson import find_lesson

SCENE = """name = "cube"
[camera]
eye = [2.5, 2.0, 3.5]
[[lights]]
position = [2, 3, 4]
[[nodes]]
mesh = "cube24"
shading = "{shading}"
color = {color}
"""

# In a process of its own (the template changes LP_NUM_THREADS and keeps its context): the
# template, then one forked child per scene, each sending back its picture's bytes as hex.
TEMPLATE = textwrap.dedent("""
    import json, os, sys
    from glsandbox.lesson import find_lesson
    from glsandbox.grading.warm import open_template, quiet
    renderer = open_template(None, [(64, 48)])
    out = {"template": renderer is not None, "pictures": [], "threads": os.listdir("/proc/self/task")}
    for path in sys.argv[1:] if renderer is not None else []:
        read, write = os.pipe()
        assert quiet()
        pid = os.fork()
        if pid == 0:
            image = renderer.render(find_lesson(path).from_settings({}), (64, 48)).image
            os.write(write, image.tobytes().hex().encode()); os._exit(0)
        os.close(write)
        data = b""
        while chunk := os.read(read, 1 << 16):
            data += chunk
        os.waitpid(pid, 0)
        out["pictures"].append(data.decode())
    print(json.dumps(out))
""")


def test_a_forked_renderer_draws_what_a_fresh_context_draws_and_nothing_of_its_siblings(gl, tmp_path: Path) -> None:
    other = tmp_path / "other.toml"
    other.write_text(SCENE.format(shading="solid", color="[0.1, 0.9, 0.1]"))
    right = tmp_path / "right.toml"
    right.write_text(SCENE.format(shading="phong", color="[0.8, 0.4, 0.2]"))
    run = subprocess.run([sys.executable, "-c", TEMPLATE, str(other), str(right), str(right)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    if "llvmpipe" not in str(gl.host.ctx.info.get("GL_RENDERER", "")):
        assert out["template"] is False  # a hardware driver is never forked after its context opens
        return
    assert out["template"] is True
    fresh = {p: np.ascontiguousarray(gl.render(find_lesson(str(p)).from_settings({}), (64, 48)).image).tobytes()
             for p in (other, right)}
    pictures = [bytes.fromhex(h) for h in out["pictures"]]
    # byte for byte what a fresh, multi-threaded context draws; the green cube drawn by the first
    # child is in no later child's picture (each is a copy of the template, not of its sibling)
    assert pictures == [fresh[other], fresh[right], fresh[right]]
    assert fresh[other] != fresh[right]
