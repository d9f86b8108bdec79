"""Poses for DeformStream.send_pose: deformctl's "JOINT:AXIS:DEGREES[,...]" text, a dict
{"joint": ..., "axis": ..., "degrees": ...}, a (joint, axis, degrees) tuple, a list of those, or a
PoseUpdate message as is. JOINT is a name or a 0-based index (the axis and the angle are read
from the right, so a name may hold colons: "mixamorig:LeftForeArm:z:60"; a name in double quotes
may hold commas and spaces: '"left arm, upper":x:30'), AXIS x, y, z or a degree of freedom's
name ("flexion"); the server resolves both. "" and "rest" are the rest pose. ValueError naming the
offending term for malformed input (the same rules as core/base/pose_spec.h).
"""

from __future__ import annotations

import math
from typing import Any, List

from .stubs import pb


def _term(joint: object, axis: object, degrees: Any, text: object) -> pb.JointAngle:
    joint = str(joint).strip()
    axis = str(axis).strip()
    if not joint or not axis:
        raise ValueError(f"pose term {text!r} is not JOINT:AXIS:DEGREES")
    try:
        value = float(degrees)
    except (TypeError, ValueError):
        raise ValueError(f"pose term {text!r}: {degrees!r} is not a finite number of degrees") \
            from None
    if not math.isfinite(value):
        raise ValueError(f"pose term {text!r}: {degrees!r} is not a finite number of degrees")
    return pb.JointAngle(joint=joint, axis=axis, degrees=value)


def _split_terms(spec: str) -> List[str]:
    """`spec` split at the commas outside double quotes."""
    terms, start, quoted = [], 0, False
    for i, char in enumerate(spec):
        if char == '"':
            quoted = not quoted
        elif char == "," and not quoted:
            terms.append(spec[start:i])
            start = i + 1
    if quoted:
        raise ValueError(f"pose {spec!r} has an unclosed '\"'")
    terms.append(spec[start:])
    return terms


def _fields(text: str) -> List[str]:
    """A term's joint, axis and degrees: the axis and the angle are the last two fields, the joint
    everything before them (names may hold colons) or a double-quoted name."""
    malformed = ValueError(f"pose term {text!r} is not JOINT:AXIS:DEGREES")
    if text.startswith('"'):
        close = text.find('"', 1)
        if close < 0:
            raise malformed
        rest = text[close + 1:].strip()
        if not rest.startswith(":") or rest[1:].count(":") != 1:
            raise malformed
        axis, degrees = rest[1:].split(":")
        return [text[1:close], axis, degrees]
    fields = text.rsplit(":", 2)
    if len(fields) != 3:
        raise malformed
    return fields


def parse_pose_spec(spec: str) -> List[pb.JointAngle]:
    """deformctl's syntax -> a list of JointAngle messages."""
    spec = spec.strip()
    if spec in ("", "rest"):
        return []
    angles = []
    for text in _split_terms(spec):
        text = text.strip()
        joint, axis, degrees = _fields(text)
        angles.append(_term(joint, axis, degrees.strip(), text))
    return angles


def angles_of(pose: object) -> List[pb.JointAngle]:
    """Any accepted pose form except a PoseUpdate -> a list of JointAngle messages."""
    if isinstance(pose, str):
        return parse_pose_spec(pose)
    if isinstance(pose, dict):
        missing = [key for key in ("joint", "axis", "degrees") if key not in pose]
        if missing:
            raise ValueError(f"pose term {pose!r} lacks {', '.join(missing)}")
        return [_term(pose["joint"], pose["axis"], pose["degrees"], pose)]
    if isinstance(pose, tuple) and len(pose) == 3 and \
            not any(isinstance(item, (tuple, list, dict)) for item in pose):
        return [_term(pose[0], pose[1], pose[2], pose)]
    if isinstance(pose, (list, tuple)):
        angles = []
        for item in pose:
            angles.extend(angles_of(item))
        return angles
    raise ValueError(f"a pose is a 'JOINT:AXIS:DEGREES' string, a dict, a (joint, axis, degrees) "
                     f"tuple or a list of them, not {type(pose).__name__}")


def pose_update(pose: object, sequence: int, timestamp_ns: int) -> pb.PoseUpdate:
    """A PoseUpdate with `sequence` and `timestamp_ns` from any accepted form (a PoseUpdate is
    copied, its sequence and timestamp kept when set)."""
    if isinstance(pose, pb.PoseUpdate):
        update = pb.PoseUpdate()
        update.CopyFrom(pose)
        if update.sequence == 0:
            update.sequence = sequence
        if update.client_timestamp_ns == 0:
            update.client_timestamp_ns = timestamp_ns
        return update
    return pb.PoseUpdate(sequence=sequence, client_timestamp_ns=timestamp_ns,
                         angles=angles_of(pose))
