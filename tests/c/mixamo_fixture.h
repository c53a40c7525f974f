/* Test fixture of the C API tests: writes a small Mixamo-named T-pose rig (22 joints, no
 * mesh, no declared humanoid) as a text glTF, so that mapping tables and .glb export can be
 * tested without the shared avatars. C99, header-only. */
#ifndef AVATARMAP_TESTS_C_MIXAMO_FIXTURE_H
#define AVATARMAP_TESTS_C_MIXAMO_FIXTURE_H

#include <stdio.h>

typedef struct fixture_joint {
  const char* name; /* without the "mixamorig:" prefix */
  int parent;
  float x, y, z; /* local rest translation, metres: Y up, facing +Z, left = +X */
} fixture_joint;

/* Parent-first; the parent is an index into this array. */
static const fixture_joint k_fixture_joints[] = {
    {"Hips", -1, 0.f, 1.f, 0.f},
    {"Spine", 0, 0.f, 0.1f, 0.f},
    {"Spine1", 1, 0.f, 0.1f, 0.f},
    {"Spine2", 2, 0.f, 0.1f, 0.f},
    {"Neck", 3, 0.f, 0.15f, 0.f},
    {"Head", 4, 0.f, 0.1f, 0.f},
    {"LeftShoulder", 3, 0.05f, 0.1f, 0.f},
    {"LeftArm", 6, 0.1f, 0.f, 0.f},
    {"LeftForeArm", 7, 0.25f, 0.f, 0.f},
    {"LeftHand", 8, 0.25f, 0.f, 0.f},
    {"RightShoulder", 3, -0.05f, 0.1f, 0.f},
    {"RightArm", 10, -0.1f, 0.f, 0.f},
    {"RightForeArm", 11, -0.25f, 0.f, 0.f},
    {"RightHand", 12, -0.25f, 0.f, 0.f},
    {"LeftUpLeg", 0, 0.1f, -0.05f, 0.f},
    {"LeftLeg", 14, 0.f, -0.45f, 0.f},
    {"LeftFoot", 15, 0.f, -0.45f, 0.f},
    {"LeftToeBase", 16, 0.f, -0.05f, 0.1f},
    {"RightUpLeg", 0, -0.1f, -0.05f, 0.f},
    {"RightLeg", 18, 0.f, -0.45f, 0.f},
    {"RightFoot", 19, 0.f, -0.45f, 0.f},
    {"RightToeBase", 20, 0.f, -0.05f, 0.1f},
};

#define FIXTURE_JOINT_COUNT ((int)(sizeof k_fixture_joints / sizeof k_fixture_joints[0]))

/* Writes the rig to `path`; returns 1 on success. */
static int write_mixamo_fixture(const char* path) {
  FILE* f = fopen(path, "w");
  int i, c, first;
  if (f == NULL) return 0;
  fprintf(f, "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n");
  fprintf(f, " \"nodes\": [\n");
  for (i = 0; i < FIXTURE_JOINT_COUNT; ++i) {
    const fixture_joint* j = &k_fixture_joints[i];
    fprintf(f, "  {\"name\": \"mixamorig:%s\", \"translation\": [%g, %g, %g]", j->name,
            (double)j->x, (double)j->y, (double)j->z);
    first = 1;
    for (c = 0; c < FIXTURE_JOINT_COUNT; ++c) {
      if (k_fixture_joints[c].parent != i) continue;
      fprintf(f, "%s%d", first ? ", \"children\": [" : ", ", c);
      first = 0;
    }
    fprintf(f, "%s}%s\n", first ? "" : "]", i + 1 < FIXTURE_JOINT_COUNT ? "," : "");
  }
  fprintf(f, " ]}\n");
  return fclose(f) == 0;
}

#endif /* AVATARMAP_TESTS_C_MIXAMO_FIXTURE_H */
