/* C API retargeting: handle life cycle, bad arguments, and (with AVATARMAP_TEST_DATA) a real
 * VRM 1.0 avatar driven by a rest pose and a bent elbow. Prints "N passed, N failed". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"

static int g_passed = 0, g_failed = 0;
#define CHECK(cond)                                                            \
  do {                                                                         \
    if (cond) {                                                                \
      ++g_passed;                                                              \
    } else {                                                                   \
      ++g_failed;                                                              \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
    }                                                                          \
  } while (0)

static void rest_pose(avm_pose* p) {
  int b;
  memset(p, 0, sizeof *p);
  p->hips_position[1] = 0.95f;
  for (b = 0; b < AVM_BONE_COUNT; ++b) p->rotations[b][3] = 1.f;
}

int main(void) {
  avm_retargeter* r = NULL;
  const char* data = getenv("AVATARMAP_TEST_DATA");
  CHECK(avm_retargeter_create(NULL, NULL, &r) == AVM_ERROR_INVALID_ARGUMENT && r == NULL);
  CHECK(avm_retargeter_create("does-not-exist.vrm", NULL, &r) == AVM_ERROR_IO && r == NULL);
  CHECK(strstr(avm_last_create_error(), "does-not-exist.vrm") != NULL);
  avm_retargeter_destroy(NULL);
  CHECK(avm_retargeter_joint_count(NULL) == 0);
  CHECK(avm_retargeter_joint_name(NULL, 0) == NULL);
  CHECK(avm_retargeter_apply(NULL, NULL, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  if (data != NULL && data[0] != '\0') {
    char path[4096];
    avm_pose pose;
    float* rot;
    float hips[3];
    int n, j, ok = 1, hips_joint, elbow;
    snprintf(path, sizeof path, "%s/avatars/vrm1_spec_53bones.vrm", data);
    CHECK(avm_retargeter_create(path, NULL, &r) == AVM_OK && r != NULL);
    if (r != NULL) {
      n = avm_retargeter_joint_count(r);
      CHECK(n == 58);
      hips_joint = avm_retargeter_bone_joint(r, AVM_BONE_HIPS);
      CHECK(hips_joint >= 0 && avm_retargeter_joint_name(r, hips_joint) != NULL);
      CHECK(avm_retargeter_joint_name(r, n) == NULL);
      rot = (float*)malloc(sizeof(float) * 4 * (size_t)n);
      rest_pose(&pose);
      CHECK(avm_retargeter_apply(r, &pose, NULL, hips) == AVM_ERROR_INVALID_ARGUMENT);
      CHECK(strlen(avm_retargeter_last_error(r)) > 0);
      CHECK(avm_retargeter_apply(r, &pose, rot, hips) == AVM_OK);
      for (j = 0; j < n; ++j) {
        float len = sqrtf(rot[4 * j] * rot[4 * j] + rot[4 * j + 1] * rot[4 * j + 1] +
                          rot[4 * j + 2] * rot[4 * j + 2] + rot[4 * j + 3] * rot[4 * j + 3]);
        if (!(fabsf(len - 1.f) < 1e-4f)) ok = 0;
      }
      CHECK(ok);
      CHECK(hips[1] > 0.5f && hips[1] < 1.5f);
      /* Bend the left elbow 90 degrees: the lower arm joint's rotation changes. */
      elbow = avm_retargeter_bone_joint(r, AVM_BONE_LEFT_LOWER_ARM);
      {
        float before[4];
        memcpy(before, rot + 4 * elbow, sizeof before);
        pose.rotations[AVM_BONE_LEFT_LOWER_ARM][1] = -0.70710678f;
        pose.rotations[AVM_BONE_LEFT_LOWER_ARM][3] = 0.70710678f;
        CHECK(avm_retargeter_apply(r, &pose, rot, NULL) == AVM_OK);
        CHECK(fabsf(before[0] * rot[4 * elbow] + before[1] * rot[4 * elbow + 1] +
                    before[2] * rot[4 * elbow + 2] + before[3] * rot[4 * elbow + 3]) < 0.8f);
      }
      free(rot);
      avm_retargeter_destroy(r);
    }
  } else {
    printf("avatar checks skipped: AVATARMAP_TEST_DATA is not set\n");
  }
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
