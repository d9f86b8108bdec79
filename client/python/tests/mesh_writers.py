"""Files the tests upload: a mesh as OBJ (float32 positions written exactly, %.9g) and a loaded
mesh's skeleton as the project's JSON (joints with rest positions and degrees of freedom, bones by
joint index), from its MeshSummary."""

import json
import pathlib


def write_obj(path, positions, triangles):
    with open(path, "w") as out:
        for x, y, z in positions:
            out.write(f"v {x:.9g} {y:.9g} {z:.9g}\n")
        for a, b, c in triangles:
            out.write(f"f {a + 1} {b + 1} {c + 1}\n")


def write_skeleton_json(path, summary):
    """The project's JSON skeleton of a loaded mesh, from its summary's joints and bones."""
    joints = [{"name": joint.name, "position": list(joint.rest_position),
               "dofs": [{"name": dof.name, "axis": list(dof.axis), "min": dof.min_degrees,
                         "max": dof.max_degrees} for dof in joint.dofs]}
              for joint in summary.joints]
    bones = [[bone.head_joint, bone.tail_joint] for bone in summary.bones]
    pathlib.Path(path).write_text(json.dumps({"joints": joints, "bones": bones}))
