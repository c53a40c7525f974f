/* C API clips: collecting poses (checks, non-finite input) and writing them as .vrma, .bvh,
 * .pose.jsonl and .glb (a generated Mixamo-named rig; with AVATARMAP_TEST_DATA also a VRM 1.0
 * avatar), the written files read back by size and content; failures name the file. Runs in
 * its own build folder (writes and removes a few small files there). Prints "N passed, N
 * failed". */
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

static int contains(const char* s, const char* part) {
  return s != NULL && strstr(s, part) != NULL;
}

/* Reads up to `size` - 1 bytes of `path` into `buf` (NUL-terminated); returns the file's
 * length, or -1 when it cannot be opened. */
static long read_file(const char* path, char* buf, size_t size) {
  FILE* f = fopen(path, "rb");
  long total = 0;
  size_t n = 0;
  char scratch[4096];
  if (f == NULL) return -1;
  if (buf != NULL && size > 0) {
    n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    total = (long)n;
  }
  for (;;) {
    size_t got = fread(scratch, 1, sizeof scratch, f);
    if (got == 0) break;
    total += (long)got;
  }
  fclose(f);
  return total;
}

static int file_exists(const char* path) {
  FILE* f = fopen(path, "rb");
  if (f == NULL) return 0;
  fclose(f);
  return 1;
}

static long count_lines(const char* path) {
  FILE* f = fopen(path, "rb");
  long lines = 0;
  int c;
  if (f == NULL) return -1;
  while ((c = fgetc(f)) != EOF) lines += c == '\n';
  fclose(f);
  return lines;
}

static int starts_with_gltf_magic(const char* path) {
  char head[8];
  return read_file(path, head, sizeof head) > 12 && memcmp(head, "glTF", 4) == 0;
}

/* Frame k of a small motion: the left elbow bends a little more each frame. */
static void motion_pose(int k, avm_pose* p) {
  int b;
  const float angle = 0.2f * (float)k;
  memset(p, 0, sizeof *p);
  p->t = 1.0 + (double)k / 30.0; /* starts at 1 s: written clips start at 0 */
  p->hips_position[1] = 0.95f;
  for (b = 0; b < AVM_BONE_COUNT; ++b) {
    p->rotations[b][3] = 1.f;
    p->confidence[b] = 1.f;
  }
  p->rotations[AVM_BONE_LEFT_LOWER_ARM][1] = -sinf(angle / 2.f);
  p->rotations[AVM_BONE_LEFT_LOWER_ARM][3] = cosf(angle / 2.f);
  p->expressions[AVM_EXPRESSION_AA] = 0.25f * (float)k;
}

static void test_collect(void) {
  avm_clip* clip = NULL;
  avm_pose p;
  CHECK(avm_clip_create(NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_last_create_error(), "avm_clip_create"));
  avm_clip_destroy(NULL);
  CHECK(avm_clip_add(NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_frame_count(NULL) == 0);
  CHECK(strcmp(avm_clip_last_error(NULL), "") == 0);
  CHECK(avm_clip_write(NULL, "x.vrma", 0.0, NULL, NULL, NULL, 0) == AVM_ERROR_INVALID_ARGUMENT);

  CHECK(avm_clip_create(&clip) == AVM_OK && clip != NULL);
  if (clip == NULL) return;
  CHECK(avm_clip_add(clip, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(clip), "NULL"));
  motion_pose(0, &p);
  p.t = NAN;
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(clip), "finite"));
  motion_pose(1, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_OK);
  CHECK(strcmp(avm_clip_last_error(clip), "") == 0);
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT); /* same time */
  motion_pose(0, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT); /* earlier */
  CHECK(contains(avm_clip_last_error(clip), "after the previous"));
  CHECK(avm_clip_frame_count(clip) == 1);
  avm_clip_destroy(clip);

  /* An empty clip cannot be written; nothing is created. */
  CHECK(avm_clip_create(&clip) == AVM_OK);
  if (clip != NULL) {
    char err[256];
    remove("c_clip_empty.vrma");
    CHECK(avm_clip_write(clip, "c_clip_empty.vrma", 0.0, NULL, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(err, "c_clip_empty.vrma") && contains(err, "no frames"));
    CHECK(strcmp(avm_clip_last_error(clip), err) == 0);
    CHECK(!file_exists("c_clip_empty.vrma"));
    avm_clip_destroy(clip);
  }
}

/* Four frames at 30 fps starting at t = 1 s; frame 2 has a NaN rotation and expression. */
static avm_clip* make_clip(void) {
  avm_clip* clip = NULL;
  avm_pose p;
  int k;
  if (avm_clip_create(&clip) != AVM_OK) return NULL;
  for (k = 0; k < 4; ++k) {
    motion_pose(k, &p);
    if (k == 2) {
      p.rotations[AVM_BONE_HEAD][0] = NAN;
      p.expressions[AVM_EXPRESSION_BLINK] = INFINITY;
      p.hips_position[0] = NAN;
    }
    CHECK(avm_clip_add(clip, &p) == AVM_OK);
  }
  CHECK(avm_clip_frame_count(clip) == 4);
  return clip;
}

static void test_write_formats(avm_clip* clip) {
  char err[512];
  char text[4096];
  long size;

  /* .vrma: a GLB. */
  CHECK(avm_clip_write(clip, "c_clip_test.vrma", 0.0, NULL, NULL, err, sizeof err) == AVM_OK);
  CHECK(strcmp(err, "") == 0);
  CHECK(starts_with_gltf_magic("c_clip_test.vrma"));
  size = read_file("c_clip_test.vrma", text, sizeof text);
  CHECK(size > 1000);
  remove("c_clip_test.vrma");
  /* ... resampled at 60 fps, upper-case extension. */
  CHECK(avm_clip_write(clip, "c_clip_test60.VRMA", 60.0, NULL, NULL, err, sizeof err) == AVM_OK);
  CHECK(starts_with_gltf_magic("c_clip_test60.VRMA"));
  remove("c_clip_test60.VRMA");

  /* .bvh: the proxy skeleton. */
  CHECK(avm_clip_write(clip, "c_clip_test.bvh", 30.0, NULL, NULL, err, sizeof err) == AVM_OK);
  size = read_file("c_clip_test.bvh", text, sizeof text);
  CHECK(size > 2000);
  CHECK(strncmp(text, "HIERARCHY", 9) == 0);
  CHECK(contains(text, "ROOT hips"));
  CHECK(read_file("c_clip_test.bvh", NULL, 0) == size);
  {
    /* The MOTION section: 4 frames at 1/30 s. */
    static char all[65536];
    CHECK(read_file("c_clip_test.bvh", all, sizeof all) == size);
    CHECK(contains(all, "Frames: 4"));
    CHECK(contains(all, "Frame Time: 0.033333"));
    CHECK(!contains(all, "nan") && !contains(all, "inf"));
  }
  remove("c_clip_test.bvh");

  /* .pose.jsonl: a header line and one line per frame, times as added at fps 0. */
  CHECK(avm_clip_write(clip, "c_clip_test.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) == AVM_OK);
  CHECK(count_lines("c_clip_test.pose.jsonl") == 5);
  size = read_file("c_clip_test.pose.jsonl", text, sizeof text);
  CHECK(size > 4 * 1000);
  CHECK(contains(text, "avatarmap.pose"));
  CHECK(contains(text, "\"t\":1"));
  {
    static char all[65536];
    CHECK(read_file("c_clip_test.pose.jsonl", all, sizeof all) == size);
    CHECK(!contains(all, "null")); /* non-finite input was taken as missing */
  }
  /* ... at 60 fps: 0.1 s -> 7 frames from t = 0. */
  CHECK(avm_clip_write(clip, "c_clip_test.pose.jsonl", 60.0, NULL, NULL, err, sizeof err) ==
        AVM_OK);
  CHECK(count_lines("c_clip_test.pose.jsonl") == 8);
  read_file("c_clip_test.pose.jsonl", text, sizeof text);
  CHECK(contains(text, "\"fps\":60"));
  CHECK(contains(text, "\"t\":0"));
  remove("c_clip_test.pose.jsonl");

  /* Failures name the file; an existing file is left alone. */
  CHECK(avm_clip_write(clip, "c_clip_test.txt", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "c_clip_test.txt") && contains(err, ".vrma"));
  CHECK(avm_clip_write(clip, "c_clip_test.vrma", -1.0, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "fps"));
  CHECK(avm_clip_write(clip, "c_clip_test.vrma", NAN, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_write(clip, "no-such-dir/c_clip_test.vrma", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "no-such-dir/c_clip_test.vrma"));
  CHECK(contains(avm_clip_last_error(clip), "no-such-dir/c_clip_test.vrma"));
  CHECK(avm_clip_write(clip, "no-such-dir/c.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "no-such-dir/c.pose.jsonl"));
  CHECK(avm_clip_write(clip, "c_clip_test.glb", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "c_clip_test.glb") && contains(err, "avatar"));
  CHECK(avm_clip_write(clip, "c_clip_test.bvh", 0.0, "no-such-avatar.vrm", NULL, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "no-such-avatar.vrm"));
  CHECK(!file_exists("c_clip_test.bvh"));
  /* A small err buffer gets a truncated, terminated message; NULL err is fine. */
  {
    char small[8];
    memset(small, 'x', sizeof small);
    CHECK(avm_clip_write(clip, "c_clip_test.txt", 0.0, NULL, NULL, small, sizeof small) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(small[7] == '\0' && strlen(small) == 7);
    CHECK(avm_clip_write(clip, "c_clip_test.txt", 0.0, NULL, NULL, NULL, 0) ==
          AVM_ERROR_INVALID_ARGUMENT);
  }
  /* A successful write clears the last error. */
  CHECK(avm_clip_write(clip, "c_clip_test.vrma", 0.0, NULL, NULL, NULL, 0) == AVM_OK);
  CHECK(strcmp(avm_clip_last_error(clip), "") == 0);
  remove("c_clip_test.vrma");
}

static void test_write_glb(avm_clip* clip) {
  char err[1024];
  const char* rig = "c_clip_mixamo.gltf";
  const char* data = getenv("AVATARMAP_TEST_DATA");
  CHECK(avm_set_mappings_folder(AVM_TEST_MAPPINGS_DIR) == AVM_OK);
  CHECK(write_mixamo_fixture(rig));
  /* The generated Mixamo rig, auto-detected, then by name. */
  CHECK(avm_clip_write(clip, "c_clip_mixamo.glb", 0.0, rig, NULL, err, sizeof err) == AVM_OK);
  if (err[0] != '\0') fprintf(stderr, "%s\n", err);
  CHECK(starts_with_gltf_magic("c_clip_mixamo.glb"));
  remove("c_clip_mixamo.glb");
  CHECK(avm_clip_write(clip, "c_clip_mixamo.glb", 24.0, rig, "mixamo", err, sizeof err) == AVM_OK);
  CHECK(starts_with_gltf_magic("c_clip_mixamo.glb"));
  remove("c_clip_mixamo.glb");
  /* The rig's own BVH: its joints and names; 0.1 s at 30 fps (the default rate) = 4 frames. */
  CHECK(avm_clip_write(clip, "c_clip_mixamo.bvh", 0.0, rig, NULL, err, sizeof err) == AVM_OK);
  {
    static char all[65536];
    CHECK(read_file("c_clip_mixamo.bvh", all, sizeof all) > 1000);
    CHECK(strncmp(all, "HIERARCHY", 9) == 0);
    CHECK(contains(all, "ROOT mixamorig:Hips"));
    CHECK(contains(all, "JOINT mixamorig:LeftForeArm"));
    CHECK(contains(all, "Frames: 4"));
  }
  remove("c_clip_mixamo.bvh");
  CHECK(avm_clip_write(clip, "c_clip_mixamo.glb", 0.0, rig, "ue4_mannequin", err, sizeof err) ==
        AVM_ERROR_PARSE);
  CHECK(contains(err, "ue4_mannequin") && contains(err, rig));
  CHECK(avm_clip_write(clip, "c_clip_mixamo.glb", 0.0, rig, "no-such.json", err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "no-such.json"));
  CHECK(avm_clip_write(clip, "c_clip_mixamo.glb", 0.0, "no-such-avatar.glb", NULL, err,
                       sizeof err) == AVM_ERROR_IO);
  CHECK(contains(err, "no-such-avatar.glb"));
  CHECK(!file_exists("c_clip_mixamo.glb"));
  remove(rig);

  if (data != NULL && data[0] != '\0') {
    char avatar[4096];
    snprintf(avatar, sizeof avatar, "%s/avatars/vrm1_spec_53bones.vrm", data);
    CHECK(avm_clip_write(clip, "c_clip_vrm1.glb", 30.0, avatar, NULL, err, sizeof err) == AVM_OK);
    if (err[0] != '\0') fprintf(stderr, "%s\n", err);
    CHECK(starts_with_gltf_magic("c_clip_vrm1.glb"));
    CHECK(read_file("c_clip_vrm1.glb", NULL, 0) > 10000);
    remove("c_clip_vrm1.glb");
    CHECK(avm_clip_write(clip, "c_clip_vrm1.glb", 30.0, avatar, "vrm1", err, sizeof err) == AVM_OK);
    remove("c_clip_vrm1.glb");
    CHECK(avm_clip_write(clip, "c_clip_vrm1.glb", 30.0, avatar, "mixamo", err, sizeof err) ==
          AVM_ERROR_PARSE);
    CHECK(contains(err, "mixamo") && contains(err, "vrm1_spec_53bones.vrm"));
    CHECK(avm_clip_write(clip, "c_clip_vrm1.bvh", 30.0, avatar, "vrm1", err, sizeof err) == AVM_OK);
    CHECK(read_file("c_clip_vrm1.bvh", NULL, 0) > 2000);
    remove("c_clip_vrm1.bvh");
  } else {
    SKIP_PART("the avatar checks need AVATARMAP_TEST_DATA (the shared data folder)");
  }
}

/* foot_contact goes into a clip, out to .pose.jsonl, back through avm_clip_read, exactly
 * (clamped to [0, 1], NaN = 0, as avm_clip_add says). */
static void test_foot_contact_round_trip(void) {
  static const float in[4][2] = {{0.f, 1.f}, {0.25f, 0.5f}, {-2.f, 7.f}, {NAN, 1.f}};
  static const float want[4][2] = {{0.f, 1.f}, {0.25f, 0.5f}, {0.f, 1.f}, {0.f, 1.f}};
  avm_clip* clip = NULL;
  avm_clip* back = NULL;
  avm_pose p, got[4];
  char err[256];
  int k;
  CHECK(avm_clip_create(&clip) == AVM_OK);
  if (clip == NULL) return;
  for (k = 0; k < 4; ++k) {
    motion_pose(k, &p);
    p.foot_contact[0] = in[k][0];
    p.foot_contact[1] = in[k][1];
    CHECK(avm_clip_add(clip, &p) == AVM_OK);
  }
  CHECK(avm_clip_write(clip, "c_clip_contact.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_OK);
  CHECK(avm_clip_read("c_clip_contact.pose.jsonl", &back, err, sizeof err) == AVM_OK);
  if (back != NULL) {
    CHECK(avm_clip_get_poses(back, 0, 4, got) == AVM_OK);
    for (k = 0; k < 4; ++k) {
      CHECK(got[k].foot_contact[0] == want[k][0]);
      CHECK(got[k].foot_contact[1] == want[k][1]);
    }
    avm_clip_destroy(back);
  }
  remove("c_clip_contact.pose.jsonl");
  avm_clip_destroy(clip);
}

/* Blendshapes and the new emotions go into a clip (non-finite = the previous frame's, 0 for
 * the first; clamped to [0, 1], as avm_clip_add says), out to .pose.jsonl and back through
 * avm_clip_read exactly. */
static void test_blendshape_round_trip(void) {
  avm_clip* clip = NULL;
  avm_clip* back = NULL;
  avm_pose p, got[3];
  char err[256];
  int k, s;
  CHECK(avm_clip_create(&clip) == AVM_OK);
  if (clip == NULL) return;
  for (k = 0; k < 3; ++k) {
    motion_pose(k, &p);
    for (s = 0; s < AVM_BLENDSHAPE_COUNT; ++s) p.blendshapes[s] = (float)(s + k) / 64.f;
    p.expressions[AVM_EXPRESSION_SURPRISED] = 0.5f * (float)k;
    if (k == 0) p.blendshapes[AVM_BLENDSHAPE_JAW_OPEN] = NAN; /* first frame: 0 */
    if (k == 1) p.blendshapes[AVM_BLENDSHAPE_CHEEK_PUFF] = INFINITY;
    if (k == 2) p.blendshapes[AVM_BLENDSHAPE_TONGUE_OUT] = 3.f;
    CHECK(avm_clip_add(clip, &p) == AVM_OK);
  }
  CHECK(avm_clip_get_poses(clip, 0, 3, got) == AVM_OK);
  CHECK(got[0].blendshapes[AVM_BLENDSHAPE_JAW_OPEN] == 0.f);
  CHECK(got[1].blendshapes[AVM_BLENDSHAPE_CHEEK_PUFF] == 5.f / 64.f); /* frame 0's */
  CHECK(got[2].blendshapes[AVM_BLENDSHAPE_TONGUE_OUT] == 1.f);
  CHECK(got[2].blendshapes[AVM_BLENDSHAPE_BROW_INNER_UP] == 4.f / 64.f);
  CHECK(got[2].expressions[AVM_EXPRESSION_SURPRISED] == 1.f);
  CHECK(avm_clip_write(clip, "c_clip_shapes.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_OK);
  CHECK(avm_clip_read("c_clip_shapes.pose.jsonl", &back, err, sizeof err) == AVM_OK);
  if (back != NULL) {
    avm_pose again[3];
    CHECK(avm_clip_get_poses(back, 0, 3, again) == AVM_OK);
    for (k = 0; k < 3; ++k) {
      CHECK(memcmp(again[k].blendshapes, got[k].blendshapes, sizeof got[k].blendshapes) == 0);
      CHECK(memcmp(again[k].expressions, got[k].expressions, sizeof got[k].expressions) == 0);
    }
    avm_clip_destroy(back);
  }
  remove("c_clip_shapes.pose.jsonl");
  avm_clip_destroy(clip);
}

int main(void) {
  avm_clip* clip;
  test_collect();
  test_foot_contact_round_trip();
  test_blendshape_round_trip();
  clip = make_clip();
  CHECK(clip != NULL);
  if (clip != NULL) {
    test_write_formats(clip);
    test_write_glb(clip);
    avm_clip_destroy(clip);
  }
  return check_exit();
}
