"""Surgical tools pressing the skin (docs/instruments.md): ToolState messages from text or tuples.

    tool_state("sphere:0,6,0.86,0.3")                    # "sphere:X,Y,Z,R"
    tool_state("capsule:-0.3,6,0.8,0.3,6,0.8,0.2")       # "capsule:X0,Y0,Z0,X1,Y1,Z1,R"
    tool_state(("sphere", (0, 6, 0.86), 0.3))
    tool_state(("capsule", (x0, y0, z0), (x1, y1, z1), r))

Model units, the posed skin's frame. A ToolState message is used as is. ValueError for malformed
input (the syntax of core/base/tool_spec.h); the server checks the values against the mesh.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, List, Sequence, Tuple, Union, cast

from .stubs import pb

Point = Sequence[float]
# One tool ("sphere:...", a ("sphere", centre, r) or ("capsule", end0, end1, r) tuple, a
# ToolState), or a list of them.
Tool = Union[str, pb.ToolState, Tuple[Any, ...]]
ToolSpec = Union[Tool, Sequence[Tool]]

MAX_TOOLS = 4  # ToolSet::kMaxTools: the server rejects a pose with more


def _finite(value: Any, text: object) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"tool {text!r}: {value!r} is not a number") from None
    if not math.isfinite(number):
        raise ValueError(f"tool {text!r}: {value!r} is not finite")
    return number


def _vector(values: Iterable[Any], text: object) -> pb.Vector3:
    values = [_finite(v, text) for v in values]
    if len(values) != 3:
        raise ValueError(f"tool {text!r}: a point needs 3 coordinates")
    return pb.Vector3(x=values[0], y=values[1], z=values[2])


def tool_state(tool: Tool) -> pb.ToolState:
    """A ToolState from any accepted form (see the module's docstring)."""
    if isinstance(tool, pb.ToolState):
        return tool
    if isinstance(tool, str):
        shape, _, rest = tool.partition(":")
        values = [_finite(v, tool) for v in rest.split(",")] if rest else []
        if shape == "sphere" and len(values) == 4:
            return pb.ToolState(shape=pb.ToolState.SHAPE_SPHERE, center=_vector(values[:3], tool),
                                radius=values[3])
        if shape == "capsule" and len(values) == 7:
            return pb.ToolState(shape=pb.ToolState.SHAPE_CAPSULE,
                                center=_vector(values[:3], tool), end=_vector(values[3:6], tool),
                                radius=values[6])
        raise ValueError(f"tool {tool!r}: expected sphere:X,Y,Z,R or capsule:X0,Y0,Z0,X1,Y1,Z1,R")
    if isinstance(tool, (tuple, list)) and tool and tool[0] == "sphere" and len(tool) == 3:
        return pb.ToolState(shape=pb.ToolState.SHAPE_SPHERE, center=_vector(tool[1], tool),
                            radius=_finite(tool[2], tool))
    if isinstance(tool, (tuple, list)) and tool and tool[0] == "capsule" and len(tool) == 4:
        return pb.ToolState(shape=pb.ToolState.SHAPE_CAPSULE, center=_vector(tool[1], tool),
                            end=_vector(tool[2], tool), radius=_finite(tool[3], tool))
    raise ValueError(f"tool {tool!r}: not a tool form")


def tool_states(tools: Union[ToolSpec, None]) -> List[pb.ToolState]:
    """A list of ToolState from one tool or a list of them (None: no tool)."""
    if tools is None:
        return []
    if isinstance(tools, (str, pb.ToolState)) or (
            isinstance(tools, tuple) and tools and isinstance(tools[0], str)):
        return [tool_state(tools)]
    return [tool_state(tool) for tool in cast(Sequence[Tool], tools)]
