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
  ok &= AVM_EXPRESSION_BROW_DOWN_RIGHT == 15 && AVM_EXPRESSION_HAPPY == 16;
  ok &= AVM_EXPRESSION_SURPRISED == AVM_EXPRESSION_COUNT - 1 && AVM_EXPRESSION_COUNT == 21;
  ok &= AVM_BLENDSHAPE_BROW_DOWN_LEFT == 0 && AVM_BLENDSHAPE_JAW_OPEN == 24;
  ok &= AVM_BLENDSHAPE_TONGUE_OUT == AVM_BLENDSHAPE_COUNT - 1 && AVM_BLENDSHAPE_COUNT == 52;
  /* 0.2.0's layout: blendshapes after foot_contact, at the end. */
  ok &= sizeof pose.blendshapes == AVM_BLENDSHAPE_COUNT * sizeof(float);
  ok &= offsetof(avm_pose, foot_contact) ==
        offsetof(avm_pose, expressions) + AVM_EXPRESSION_COUNT * sizeof(float);
  ok &= offsetof(avm_pose, blendshapes) == offsetof(avm_pose, foot_contact) + 2 * sizeof(float);
  /* ... then only the padding up to the double's alignment (4 bytes: 1424 in all). */
  ok &= sizeof pose - (offsetof(avm_pose, blendshapes) + sizeof pose.blendshapes) < sizeof(double);
  ok &= sizeof pose == 1424;
  ok &= AVM_OK == 0 && status == AVM_OK && solver == NULL;
  (void)frame;
  if (!ok) {
    fprintf(stderr, "avatarmap.h: unexpected layout\n");
    return 1;
  }
  return 0;
}
