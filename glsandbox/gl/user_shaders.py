"""A node's own shader program (``Node.shader``): what it read and declares, and the values
a scene sets in it (``Node.uniforms``, ``--set u.NAME``) checked against its uniforms."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass
from pathlib import Path

import moderngl

from glsandbox.errors import SandboxError
from glsandbox.gl.gpu_meshes import _ATTRIBUTES
from glsandbox.scene import Node

@dataclass(frozen=True)
class UserProgram:
    """What the executor knows of a node's own shader program besides the program itself."""

    path: Path  # the user's file
    files: frozenset[Path]  # it and every file it includes (watched by the window)
    declared: frozenset[str]  # the uniform names its text declares


#: GL types of the uniforms a scene may set (``Node.uniforms``, ``--set u.NAME``):
#: GLSL name, component kind, component count.
_SETTABLE_UNIFORMS = {
    0x1406: ("float", "float", 1), 0x8B50: ("vec2", "float", 2), 0x8B51: ("vec3", "float", 3),
    0x8B52: ("vec4", "float", 4), 0x1404: ("int", "int", 1), 0x8B53: ("ivec2", "int", 2),
    0x8B54: ("ivec3", "int", 3), 0x8B55: ("ivec4", "int", 4), 0x1405: ("uint", "uint", 1),
    0x8DC6: ("uvec2", "uint", 2), 0x8DC7: ("uvec3", "uint", 3), 0x8DC8: ("uvec4", "uint", 4),
    0x8B56: ("bool", "bool", 1),
}
#: Other GL types, named in errors.
_OTHER_TYPES = {0x8B5A: "mat2", 0x8B5B: "mat3", 0x8B5C: "mat4", 0x8B5E: "sampler2D", 0x8B60: "samplerCube",
                0x8B57: "bvec2", 0x8B58: "bvec3", 0x8B59: "bvec4"}
#: The attributes the executor feeds, with the GLSL type of what their buffers hold.
_ATTRIBUTE_GLSL = {attr: f"vec{width}" for _, attr, width in _ATTRIBUTES}
#: GL's float, vec2, vec3, vec4: the types a buffer of floats can feed.
_FLOAT_VECTORS = (0x1406, 0x8B50, 0x8B51, 0x8B52)


def user_uniform_value(user: UserProgram, uniform: moderngl.Uniform, name: str, value: object,
                       given_by: str) -> object:
    """``value`` as ``uniform`` takes it, or a :class:`SandboxError` naming the user's file:
    a number for float, int and uint (whole numbers for the last two), a bool for bool,
    N numbers for vecN, ivecN and uvecN; arrays, matrices and samplers are not set this way."""
    settable = _SETTABLE_UNIFORMS.get(uniform.gl_type)
    glsl = settable[0] if settable else _OTHER_TYPES.get(uniform.gl_type, f"GL type 0x{uniform.gl_type:04X}")
    if uniform.array_length > 1:
        glsl += f"[{uniform.array_length}]"
    if settable is None or uniform.array_length > 1:
        raise SandboxError(f"{user.path}: uniform {name} is a {glsl}; {given_by} may set float, int, uint, bool, "
                           "vecN, ivecN and uvecN uniforms only")
    _, kind, count = settable
    items = value if isinstance(value, tuple) else (value,)
    fits = len(items) == count and all(isinstance(v, bool) == (kind == "bool") for v in items)
    if fits and kind in ("int", "uint"):
        fits = all(float(v).is_integer() and (kind == "int" or v >= 0) for v in items)
    if not fits:
        shown = ("true" if value else "false") if isinstance(value, bool) else \
            ", ".join(f"{v:g}" for v in items) if len(items) > 1 else f"{items[0]:g}"
        raise SandboxError(f"{user.path}: uniform {name} is a {glsl}, but {given_by} gives it {shown}")
    if kind in ("int", "uint"):
        items = tuple(int(v) for v in items)
    return items if count > 1 else items[0]


def check_user_draw(overrides: Mapping[str, object], user: UserProgram, program: moderngl.Program,
                    members: Collection[str], node: Node) -> dict[str, object]:
    """The values to write into a node's own shader program, each checked against the program.

    Also checks the attributes against the node's mesh. The node's ``uniforms``
    must be declared by the shader (a typo is an error); one declared but
    unused has no uniform in the program, and is skipped as GL would. A
    ``--set u.NAME`` value applies where the shader declares NAME.
    """
    for name in members:
        member = program[name]
        if not isinstance(member, moderngl.Attribute):
            continue
        if name not in _ATTRIBUTE_GLSL:
            raise SandboxError(f"{user.path}: attribute {name} is none the renderer gives "
                               f"({', '.join(_ATTRIBUTE_GLSL)})")
        glsl = _ATTRIBUTE_GLSL[name]
        # GL converts the buffer's floats to any float vector (missing y, z are 0, w is 1:
        # 'in vec4 in_position' works); integer or matrix attributes it cannot feed.
        if member.gl_type not in _FLOAT_VECTORS:
            raise SandboxError(f"{user.path}: attribute {name} must be a float vector: 'in {glsl} {name}'")
        array = {"in_uv": "uvs", "in_color": "colors"}.get(name)
        if array and getattr(node.mesh, array) is None:
            what = "texture coordinates (uvs)" if array == "uvs" else "vertex colours"
            raise SandboxError(f"{user.path}: in {glsl} {name} needs {what}, which node {node.name!r}'s "
                               f"mesh {node.mesh.name!r} does not have")
    values = {}
    for name, value in node.uniforms.items():
        if name not in user.declared:
            raise SandboxError(f"{user.path}: node {node.name!r} sets uniform {name}, which the shader does not "
                               f"declare (it declares: {', '.join(sorted(user.declared)) or 'none'})")
        if name in members:
            values[name] = user_uniform_value(user, program[name], name, value, f"node {node.name!r}")
    for name, value in overrides.items():
        if name in members and name in user.declared:
            values[name] = user_uniform_value(user, program[name], name, value, f"--set u.{name}")
    return values
