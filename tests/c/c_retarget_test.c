/* C API retargeting: handle life cycle, bad arguments, mapping tables (auto-detection, by
 * name, a .json path, a table with formulas, failures) on a generated Mixamo-named rig, and
 * (with AVATARMAP_TEST_DATA) a real VRM 1.0 avatar driven by a rest pose and a bent elbow,
 * with the VRM tables by name. Runs in its own build folder (writes a few small files there).
 * AVM_TEST_MAPPINGS_DIR is the source tree's mappings/ folder. Prints "N passed, N failed". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "mixamo_fixture.h"

#ifndef AVM_TEST_MAPPINGS_DIR
#error "AVM_TEST_MAPPINGS_DIR must name the mappings folder"
#endif

static void rest_pose(avm_pose* p) {
  int b;
  memset(p, 0, sizeof *p);
  p->hips_position[1] = 0.95f;
  for (b = 0; b < AVM_BONE_COUNT; ++b) p->rotations[b][3] = 1.f;
}

static int contains(const char* s, const char* part) {
  return s != NULL && strstr(s, part) != NULL;
}

static int write_text(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  if (f == NULL) return 0;
  fputs(text, f);
  return fclose(f) == 0;
}

/* Joint index of the rig joint named `name`, or -1. */
static int joint_named(const avm_retargeter* r, const char* name) {
  int j, n = avm_retargeter_joint_count(r);
  for (j = 0; j < n; ++j)
    if (strcmp(avm_retargeter_joint_name(r, j), name) == 0) return j;
  return -1;
}

static const char* k_rig = "c_retarget_mixamo.gltf";

/* Mapping tables on the generated Mixamo rig. */
static void test_mapping_tables(void) {
  avm_retargeter* r = NULL;
  const char* env = getenv("AVATARMAP_MAPPINGS");
  const int env_set = env != NULL && env[0] != '\0';
  CHECK(write_mixamo_fixture(k_rig));

  /* No folder given: the library finds its own tables (io/resources.hpp: here the source
   * tree's, as avm_find_resource says). */
  CHECK(avm_set_mappings_folder(NULL) == AVM_OK);
  if (!env_set) {
    char folder[4096], rule[64];
    CHECK(avm_find_resource(AVM_RESOURCE_MAPPINGS, NULL, folder, sizeof folder, rule, sizeof rule,
                            NULL, 0) == AVM_OK);
    CHECK(strcmp(rule, "source tree") == 0 || strcmp(rule, "installed") == 0);
    CHECK(avm_retargeter_create(k_rig, NULL, &r) == AVM_OK && r != NULL);
    if (r != NULL) CHECK(contains(avm_retargeter_binding_description(r), "detected mixamo"));
    avm_retargeter_destroy(r);
    r = NULL;
    /* A .json path needs no folder. */
    CHECK(avm_retargeter_create(k_rig, AVM_TEST_MAPPINGS_DIR "/mixamo.json", &r) == AVM_OK);
    avm_retargeter_destroy(r);
    r = NULL;
    /* A folder that does not exist. */
    CHECK(avm_set_mappings_folder("no-such-mappings-folder") == AVM_OK);
    CHECK(avm_retargeter_create(k_rig, "auto", &r) == AVM_ERROR_IO && r == NULL);
    CHECK(contains(avm_last_create_error(), "no-such-mappings-folder"));
  }
  CHECK(avm_set_mappings_folder(AVM_TEST_MAPPINGS_DIR) == AVM_OK);

  /* Auto-detection. */
  CHECK(avm_retargeter_create(k_rig, NULL, &r) == AVM_OK && r != NULL);
  if (r != NULL) {
    CHECK(strcmp(avm_last_create_error(), "") == 0);
    CHECK(contains(avm_retargeter_binding_description(r), "detected mixamo"));
    CHECK(avm_retargeter_joint_count(r) == FIXTURE_JOINT_COUNT);
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_HIPS) == joint_named(r, "mixamorig:Hips"));
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_LEFT_LOWER_ARM) ==
          joint_named(r, "mixamorig:LeftForeArm"));
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_LEFT_THUMB_PROXIMAL) == -1);
    avm_retargeter_destroy(r);
    r = NULL;
  }
  CHECK(strcmp(avm_retargeter_binding_description(NULL), "") == 0);

  /* By name, explicitly "auto". */
  CHECK(avm_retargeter_create(k_rig, "mixamo", &r) == AVM_OK && r != NULL);
  CHECK(contains(avm_retargeter_binding_description(r), "table mixamo"));
  avm_retargeter_destroy(r);
  r = NULL;
  CHECK(avm_retargeter_create(k_rig, "auto", &r) == AVM_OK && r != NULL);
  avm_retargeter_destroy(r);
  r = NULL;

  /* A table of another family does not fit: the message names it and the missing bones. */
  CHECK(avm_retargeter_create(k_rig, "ue5_mannequin", &r) == AVM_ERROR_PARSE && r == NULL);
  CHECK(contains(avm_last_create_error(), "ue5_mannequin"));
  CHECK(contains(avm_last_create_error(), "missing required"));
  CHECK(contains(avm_last_create_error(), k_rig));

  /* An unknown name lists the shipped tables. */
  CHECK(avm_retargeter_create(k_rig, "nonexistent", &r) == AVM_ERROR_INVALID_ARGUMENT && r == NULL);
  CHECK(contains(avm_last_create_error(), "'nonexistent'"));
  CHECK(contains(avm_last_create_error(), "mixamo"));

  /* A .json path. */
  CHECK(avm_retargeter_create(k_rig, AVM_TEST_MAPPINGS_DIR "/mixamo.json", &r) == AVM_OK);
  CHECK(contains(avm_retargeter_binding_description(r), "mixamo.json"));
  avm_retargeter_destroy(r);
  r = NULL;

  /* Bad table paths: missing (IO), malformed (PARSE), both named. */
  CHECK(avm_retargeter_create(k_rig, "no-such-table.json", &r) == AVM_ERROR_IO && r == NULL);
  CHECK(contains(avm_last_create_error(), "no-such-table.json"));
  CHECK(write_text("c_retarget_bad.json", "{\"format_version\": 1, \"bones\": {}}"));
  CHECK(avm_retargeter_create(k_rig, "c_retarget_bad.json", &r) == AVM_ERROR_PARSE && r == NULL);
  CHECK(contains(avm_last_create_error(), "c_retarget_bad.json"));
  CHECK(contains(avm_last_create_error(), "name"));
  CHECK(write_text("c_retarget_broken.json", "{\"format_version\": 1, "));
  CHECK(avm_retargeter_create(k_rig, "c_retarget_broken.json", &r) == AVM_ERROR_PARSE);
  CHECK(contains(avm_last_create_error(), "invalid JSON"));

  /* A table with formulas: the left forearm ignores the proxy (fx = fy = fz = 0, rest 0), so
   * bending the proxy's left elbow leaves its local rotation identity, while the right one
   * (no formula) bends. */
  CHECK(write_text("c_retarget_formula.json",
                   "{\"format_version\": 1, \"name\": \"formula_test\",\n"
                   " \"recognize\": {\"prefixes\": [\"mixamorig:\"]},\n"
                   " \"bones\": {\"hips\": {\"rig\": \"Hips\"},\n"
                   "  \"rightLowerArm\": {\"rig\": \"RightForeArm\"},\n"
                   "  \"leftLowerArm\": {\"rig\": \"LeftForeArm\", \"order\": \"XYZ\",\n"
                   "                    \"f\": [\"0\", \"0\", \"0\"], \"rest\": [0, 0, 0]}}}\n"));
  CHECK(avm_retargeter_create(k_rig, "c_retarget_formula.json", &r) == AVM_OK && r != NULL);
  if (r != NULL) {
    avm_pose pose;
    float rot[4 * FIXTURE_JOINT_COUNT];
    const int left = joint_named(r, "mixamorig:LeftForeArm");
    const int right = joint_named(r, "mixamorig:RightForeArm");
    CHECK(contains(avm_retargeter_binding_description(r), "formula_test"));
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_LEFT_LOWER_ARM) == left && left >= 0);
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_SPINE) == -1);
    rest_pose(&pose);
    pose.rotations[AVM_BONE_LEFT_LOWER_ARM][1] = -0.70710678f;
    pose.rotations[AVM_BONE_LEFT_LOWER_ARM][3] = 0.70710678f;
    pose.rotations[AVM_BONE_RIGHT_LOWER_ARM][1] = 0.70710678f;
    pose.rotations[AVM_BONE_RIGHT_LOWER_ARM][3] = 0.70710678f;
    CHECK(avm_retargeter_apply(r, &pose, rot, NULL) == AVM_OK);
    CHECK(fabsf(rot[4 * left + 3]) > 0.9999f);
    CHECK(fabsf(rot[4 * right + 3]) < 0.8f);
    avm_retargeter_destroy(r);
    r = NULL;
  }
  remove("c_retarget_bad.json");
  remove("c_retarget_broken.json");
  remove("c_retarget_formula.json");
  remove(k_rig);
}

/* Foot locking through the handle: options and their defaults, a planted foot changes the
 * leg while the hips drift (and only with locking on), a free foot in the air is untouched,
 * NaN contacts give finite output. The lock's geometry is tested in tests/rig/. */
static void test_foot_lock(void) {
  avm_retargeter_options o;
  avm_retargeter* on = NULL;
  avm_retargeter* off = NULL;
  avm_pose pose;
  float a[4 * 64], b[4 * 64], hips_a[3], hips_b[3];
  int i, j, n, thigh, differs = 0, same = 1, finite = 1;
  CHECK(write_mixamo_fixture(k_rig));
  memset(&o, 0xff, sizeof o);
  CHECK(avm_retargeter_options_init(&o) == AVM_OK);
  CHECK(o.struct_size == sizeof o && o.foot_lock == 1 && o.foot_lock_align_foot == 1 &&
        o.foot_lock_lower_hips == 1 && o.foot_lock_keep_above_floor == 1);
  CHECK(avm_retargeter_options_init_sized(&o, 4) == AVM_ERROR_INVALID_ARGUMENT);
  o.struct_size = 0;
  CHECK(avm_retargeter_create_with_options(k_rig, "mixamo", &o, &on) ==
            AVM_ERROR_INVALID_ARGUMENT &&
        on == NULL);
  CHECK(contains(avm_last_create_error(), "struct_size"));
  CHECK(avm_retargeter_options_init(&o) == AVM_OK);
  CHECK(avm_retargeter_create_with_options(k_rig, "mixamo", &o, &on) == AVM_OK && on != NULL);
  o.foot_lock = 0;
  CHECK(avm_retargeter_create_with_options(k_rig, "mixamo", &o, &off) == AVM_OK && off != NULL);
  if (on == NULL || off == NULL) {
    avm_retargeter_destroy(on);
    avm_retargeter_destroy(off);
    return;
  }
  /* Every leg of the fixture has its toes: no foot-lock sentence in the description. */
  CHECK(!contains(avm_retargeter_binding_description(on), "foot locking"));
  n = avm_retargeter_joint_count(on);
  CHECK(n <= 64);
  thigh = avm_retargeter_bone_joint(on, AVM_BONE_LEFT_UPPER_LEG);
  for (i = 0; i < 30; ++i) {
    rest_pose(&pose);
    pose.t = i / 30.0;
    pose.hips_position[0] = 0.004f * (float)i; /* drifting sideways */
    pose.hips_position[1] = 0.93f;
    pose.foot_contact[0] = 1.f;
    CHECK(avm_retargeter_apply(on, &pose, a, hips_a) == AVM_OK);
    CHECK(avm_retargeter_apply(off, &pose, b, hips_b) == AVM_OK);
    if (i > 5 &&
        fabsf(a[4 * thigh + 3] - b[4 * thigh + 3]) + fabsf(a[4 * thigh + 2] - b[4 * thigh + 2]) >
            1e-3f)
      differs = 1;
  }
  CHECK(differs);
  /* Contact 0 and the feet in the air: the lock leaves the pose as retargeted. */
  avm_retargeter_reset(on);
  avm_retargeter_reset(NULL);
  rest_pose(&pose);
  pose.hips_position[1] = 1.1f;
  CHECK(avm_retargeter_apply(on, &pose, a, hips_a) == AVM_OK);
  CHECK(avm_retargeter_apply(off, &pose, b, hips_b) == AVM_OK);
  for (j = 0; j < 4 * n; ++j)
    if (a[j] != b[j]) same = 0;
  for (j = 0; j < 3; ++j)
    if (hips_a[j] != hips_b[j]) same = 0;
  CHECK(same);
  pose.foot_contact[0] = NAN;
  pose.foot_contact[1] = 1.f;
  pose.hips_position[1] = 0.5f;
  CHECK(avm_retargeter_apply(on, &pose, a, hips_a) == AVM_OK);
  for (j = 0; j < 4 * n; ++j)
    if (!isfinite(a[j])) finite = 0;
  for (j = 0; j < 3; ++j)
    if (!isfinite(hips_a[j])) finite = 0;
  CHECK(finite);
  avm_retargeter_destroy(on);
  avm_retargeter_destroy(off);
  remove(k_rig);
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
  test_mapping_tables();
  test_foot_lock();
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
      CHECK(contains(avm_retargeter_binding_description(r), "VRM 1.0 humanoid declared"));
      avm_retargeter_destroy(r);
      r = NULL;
    }
    /* VRM tables by name: "vrm1" binds through the declared humanoid; the VRM 0.x and Mixamo
     * tables fail, naming the table and the avatar. */
    CHECK(avm_retargeter_create(path, "vrm1", &r) == AVM_OK && r != NULL);
    CHECK(contains(avm_retargeter_binding_description(r), "table vrm1"));
    CHECK(avm_retargeter_bone_joint(r, AVM_BONE_HIPS) >= 0);
    avm_retargeter_destroy(r);
    r = NULL;
    CHECK(avm_retargeter_create(path, "vrm0", &r) == AVM_ERROR_PARSE && r == NULL);
    CHECK(contains(avm_last_create_error(), "vrm0") &&
          contains(avm_last_create_error(), "vrm1_spec_53bones.vrm"));
    CHECK(avm_retargeter_create(path, "mixamo", &r) == AVM_ERROR_PARSE && r == NULL);
    CHECK(contains(avm_last_create_error(), "mixamo") &&
          contains(avm_last_create_error(), "does not fit"));
  } else {
    SKIP_PART("the avatar checks need AVATARMAP_TEST_DATA (the shared data folder)");
  }
  return check_exit();
}
