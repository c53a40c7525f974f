/* Consumer of the C API: create a solver, push an empty frame, read the pose. */
#include <avatarmap/avatarmap.h>
#include <stdio.h>
#include <string.h>

int main(void) {
  avm_solver* solver = NULL;
  avm_frame frame;
  avm_pose pose;
  avm_status st;
  int major = 0, minor = 0, patch = 0;

  avm_version(&major, &minor, &patch);
  if (major != AVM_VERSION_MAJOR || minor != AVM_VERSION_MINOR) {
    fprintf(stderr, "header %s, library %s\n", AVM_VERSION_STRING, avm_version_string());
    return 1;
  }
  st = avm_solver_create(NULL, &solver);
  if (st != AVM_OK) {
    fprintf(stderr, "avm_solver_create: %s: %s\n", avm_status_string(st), avm_last_create_error());
    return 1;
  }
  memset(&frame, 0, sizeof frame); /* every part NULL: nothing seen */
  frame.t = 0.0;
  st = avm_solver_push(solver, &frame);
  if (st == AVM_OK) st = avm_solver_get_pose(solver, &pose);
  if (st != AVM_OK) {
    fprintf(stderr, "avm_solver: %s: %s\n", avm_status_string(st), avm_solver_last_error(solver));
    avm_solver_destroy(solver);
    return 1;
  }
  printf("avatarmap %s: hips [%g %g %g %g]\n", avm_version_string(),
         pose.rotations[AVM_BONE_HIPS][0], pose.rotations[AVM_BONE_HIPS][1],
         pose.rotations[AVM_BONE_HIPS][2], pose.rotations[AVM_BONE_HIPS][3]);
  avm_solver_destroy(solver);
  return 0;
}
