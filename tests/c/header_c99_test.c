/* Compiles avatarmap.h alone as strict C99 (-std=c99 -pedantic -Werror) and checks at run
 * time that its types have the layout FFI users rely on. No library calls: this target does
 * not link avatarmap_c. */
#include <stddef.h>
#include <stdio.h>

#include "avatarmap/avatarmap.h"

int main(void) {
  avm_pose pose;
  avm_frame frame;
  avm_solver_options options;
  avm_landmark landmark;
  avm_solver* solver = NULL;
  avm_status status = AVM_OK;
  int ok = 1;
  ok &= sizeof landmark == 5 * sizeof(float);
  ok &= sizeof pose.rotations == AVM_BONE_COUNT * 4 * sizeof(float);
  ok &= sizeof pose.expressions == AVM_EXPRESSION_COUNT * sizeof(float);
  ok &= offsetof(avm_solver_options, struct_size) == 0;
  ok &= sizeof options % 4 == 0;
  ok &= offsetof(avm_frame, t) == 0;
  ok &= AVM_BONE_RIGHT_LITTLE_DISTAL == AVM_BONE_COUNT - 1;
  ok &= AVM_EXPRESSION_BROW_DOWN_RIGHT == AVM_EXPRESSION_COUNT - 1;
  ok &= AVM_OK == 0 && status == AVM_OK && solver == NULL;
  (void)frame;
  if (!ok) {
    fprintf(stderr, "avatarmap.h: unexpected layout\n");
    return 1;
  }
  return 0;
}
