/* The layout of every struct of deform_c.h as this C compiler lays it out, one line per field:
 * "STRUCT SIZE INDEX OFFSET" (INDEX: the field's place in the struct). DeformBindingTest.cs
 * checks client/csharp/Deform.cs's P/Invoke structs against these lines
 * (tests/client/csharp_binding_test.sh). */
#include <stddef.h>
#include <stdio.h>

#include "deform_c.h"

#define FIELD(type, index, field) \
  printf("%s %zu %d %zu\n", #type, sizeof(type), index, offsetof(type, field))

int main(void) {
  /* deform_connect_options */
  FIELD(deform_connect_options, 0, target);
  FIELD(deform_connect_options, 1, tls);
  FIELD(deform_connect_options, 2, ca_file);
  FIELD(deform_connect_options, 3, cert_file);
  FIELD(deform_connect_options, 4, key_file);
  FIELD(deform_connect_options, 5, ca_pem);
  FIELD(deform_connect_options, 6, cert_pem);
  FIELD(deform_connect_options, 7, key_pem);
  FIELD(deform_connect_options, 8, server_name);
  FIELD(deform_connect_options, 9, token);
  FIELD(deform_connect_options, 10, unary_deadline_ms);
  FIELD(deform_connect_options, 11, connect_timeout_ms);
  /* deform_joint_info */
  FIELD(deform_joint_info, 0, name);
  FIELD(deform_joint_info, 1, rest_position);
  FIELD(deform_joint_info, 2, dof_count);
  FIELD(deform_joint_info, 3, has_region);
  /* deform_dof_info */
  FIELD(deform_dof_info, 0, name);
  FIELD(deform_dof_info, 1, axis);
  FIELD(deform_dof_info, 2, min_degrees);
  FIELD(deform_dof_info, 3, max_degrees);
  /* deform_bone_surface_info */
  FIELD(deform_bone_surface_info, 0, name);
  FIELD(deform_bone_surface_info, 1, bone);
  FIELD(deform_bone_surface_info, 2, blend_bone);
  FIELD(deform_bone_surface_info, 3, blend);
  FIELD(deform_bone_surface_info, 4, vertex_count);
  FIELD(deform_bone_surface_info, 5, triangle_count);
  /* deform_joint_angle */
  FIELD(deform_joint_angle, 0, joint);
  FIELD(deform_joint_angle, 1, axis);
  FIELD(deform_joint_angle, 2, degrees);
  /* deform_joint_rotation */
  FIELD(deform_joint_rotation, 0, joint);
  FIELD(deform_joint_rotation, 1, w);
  FIELD(deform_joint_rotation, 2, x);
  FIELD(deform_joint_rotation, 3, y);
  FIELD(deform_joint_rotation, 4, z);
  /* deform_root_transform */
  FIELD(deform_root_transform, 0, tx);
  FIELD(deform_root_transform, 1, ty);
  FIELD(deform_root_transform, 2, tz);
  FIELD(deform_root_transform, 3, qw);
  FIELD(deform_root_transform, 4, qx);
  FIELD(deform_root_transform, 5, qy);
  FIELD(deform_root_transform, 6, qz);
  /* deform_tool */
  FIELD(deform_tool, 0, shape);
  FIELD(deform_tool, 1, center);
  FIELD(deform_tool, 2, end);
  FIELD(deform_tool, 3, radius);
  /* deform_joint_material */
  FIELD(deform_joint_material, 0, joint);
  FIELD(deform_joint_material, 1, rigid);
  FIELD(deform_joint_material, 2, soft);
  FIELD(deform_joint_material, 3, seam);
  /* deform_region_weight */
  FIELD(deform_region_weight, 0, joint);
  FIELD(deform_region_weight, 1, weight);
  /* deform_frame_info */
  FIELD(deform_frame_info, 0, sequence);
  FIELD(deform_frame_info, 1, client_timestamp_ns);
  FIELD(deform_frame_info, 2, latency_ms);
  FIELD(deform_frame_info, 3, age_ms);
  FIELD(deform_frame_info, 4, frames_dropped);
  FIELD(deform_frame_info, 5, skipped_poses);
  FIELD(deform_frame_info, 6, clamped_angles);
  FIELD(deform_frame_info, 7, stiffness_version);
  FIELD(deform_frame_info, 8, server_ms);
  FIELD(deform_frame_info, 9, vertex_count);
  FIELD(deform_frame_info, 10, mesh_unloaded);
  /* deform_frame_constraints */
  FIELD(deform_frame_constraints, 0, constrained);
  FIELD(deform_frame_constraints, 1, penetrating_before);
  FIELD(deform_frame_constraints, 2, penetrating_after);
  FIELD(deform_frame_constraints, 3, max_depth_after);
  FIELD(deform_frame_constraints, 4, unresolved);
  FIELD(deform_frame_constraints, 5, contacts);
  FIELD(deform_frame_constraints, 6, volume_change);
  FIELD(deform_frame_constraints, 7, constraint_ms);
  FIELD(deform_frame_constraints, 8, bone_surface_count);
  /* deform_frame_tools */
  FIELD(deform_frame_tools, 0, penetrating_before);
  FIELD(deform_frame_tools, 1, penetrating_after);
  FIELD(deform_frame_tools, 2, max_depth_after);
  FIELD(deform_frame_tools, 3, contacts);
  FIELD(deform_frame_tools, 4, unresolved);
  /* deform_contact_result */
  FIELD(deform_contact_result, 0, sequence);
  FIELD(deform_contact_result, 1, point);
  FIELD(deform_contact_result, 2, normal);
  FIELD(deform_contact_result, 3, depth);
  FIELD(deform_contact_result, 4, force);
  FIELD(deform_contact_result, 5, signed_distance);
  FIELD(deform_contact_result, 6, material_weight);
  FIELD(deform_contact_result, 7, frame_number);
  FIELD(deform_contact_result, 8, frame_sequence);
  /* deform_notice_info */
  FIELD(deform_notice_info, 0, kind);
  FIELD(deform_notice_info, 1, sequence);
  FIELD(deform_notice_info, 2, stiffness_version);
  FIELD(deform_notice_info, 3, factor_ms);
  return 0;
}
