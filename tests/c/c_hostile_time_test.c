/* Hostile clip times through the C API: clips whose frames lie absurdly far apart (10^6 s,
 * a key at 10^9 s, 1.7e308 s) or that would resample into more frames than the documented
 * limit (avatarmap/time/resample_clip.hpp: 86400 s, 4194304 frames) are refused by
 * avm_clip_write with AVM_ERROR_INVALID_ARGUMENT and a short message naming the file and the
 * limit, before any allocation; nothing is written and an existing file is left alone. Times
 * out of order or not finite are refused by avm_clip_add. The limits exactly at the bound
 * pass. Prints "N passed, N failed". */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "test_util.h"

/* A clip of two rest poses at t0 and t1 (NULL when they cannot be added). */
static avm_clip* two_frames(double t0, double t1) {
  avm_clip* clip = NULL;
  avm_pose p;
  if (avm_clip_create(&clip) != AVM_OK) return NULL;
  rest_pose(t0, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_OK);
  rest_pose(t1, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_OK);
  return clip;
}

/* Writing `clip` to `path` at `fps` must fail with AVM_ERROR_INVALID_ARGUMENT, a message that
 * names the file and contains `words`, is shorter than 400 characters (no 300-digit numbers)
 * and equals avm_clip_last_error(); no file may appear. */
static void expect_refused(avm_clip* clip, const char* path, double fps, const char* avatar,
                           const char* words) {
  char err[1024];
  remove(path);
  CHECK(avm_clip_write(clip, path, fps, avatar, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, path));
  CHECK(contains(err, words));
  CHECK(strlen(err) < 400);
  CHECK(strcmp(avm_clip_last_error(clip), err) == 0);
  CHECK(!file_exists(path));
  if (!contains(err, words)) fprintf(stderr, "  message was: %s\n", err);
}

static void test_huge_gaps(void) {
  avm_clip* clip = two_frames(0.0, 1e6); /* 60 million frames at 60 fps */
  if (clip == NULL) return;
  expect_refused(clip, "c_hostile_gap.vrma", 60.0, NULL, "86400 s");
  expect_refused(clip, "c_hostile_gap.vrma", 0.0, NULL, "86400 s");
  expect_refused(clip, "c_hostile_gap.bvh", 30.0, NULL, "86400 s");
  expect_refused(clip, "c_hostile_gap.pose.jsonl", 60.0, NULL, "86400 s");
  expect_refused(clip, "c_hostile_gap.pose.jsonl", 0.0, NULL, "86400 s");
  /* Avatar outputs: refused before the avatar is even opened (it does not exist). */
  expect_refused(clip, "c_hostile_gap.glb", 0.0, "c_hostile_no_such_avatar.vrm", "86400 s");
  expect_refused(clip, "c_hostile_gap_rig.bvh", 0.0, "c_hostile_no_such_avatar.vrm", "86400 s");
  avm_clip_destroy(clip);

  clip = two_frames(0.0, 1e9); /* a key at 10^9 s */
  if (clip != NULL) {
    expect_refused(clip, "c_hostile_key.vrma", 1.0, NULL, "span 1e+09 s");
    avm_clip_destroy(clip);
  }
  clip = two_frames(0.0, 1.7e308); /* printed as 1.7e+308, not 309 digits */
  if (clip != NULL) {
    expect_refused(clip, "c_hostile_far.vrma", 30.0, NULL, "1.7e+308");
    avm_clip_destroy(clip);
  }
}

static void test_existing_file_kept(void) {
  const char* path = "c_hostile_keep.pose.jsonl";
  char err[512];
  char text[64] = "";
  FILE* f = fopen(path, "wb");
  avm_clip* clip = two_frames(0.0, 1e6);
  CHECK(f != NULL);
  if (f != NULL) {
    fputs("precious\n", f);
    fclose(f);
  }
  if (clip != NULL) {
    CHECK(avm_clip_write(clip, path, 60.0, NULL, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    avm_clip_destroy(clip);
  }
  f = fopen(path, "rb");
  CHECK(f != NULL);
  if (f != NULL) {
    CHECK(fgets(text, sizeof text, f) != NULL);
    fclose(f);
  }
  CHECK(strcmp(text, "precious\n") == 0);
  remove(path);
}

static void test_limits(void) {
  char err[512];
  /* Exactly 24 h between two frames at the frames' own times: written (2 lines + header). */
  avm_clip* clip = two_frames(5.0, 5.0 + 86400.0);
  if (clip != NULL) {
    CHECK(avm_clip_write(clip, "c_hostile_day.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) ==
          AVM_OK);
    CHECK(strcmp(err, "") == 0);
    CHECK(file_exists("c_hostile_day.pose.jsonl"));
    remove("c_hostile_day.pose.jsonl");
    avm_clip_destroy(clip);
  }
  /* A millisecond more: refused. */
  clip = two_frames(5.0, 5.0 + 86400.001);
  if (clip != NULL) {
    expect_refused(clip, "c_hostile_day.pose.jsonl", 0.0, NULL, "24 h");
    avm_clip_destroy(clip);
  }
  /* 41943.04 s at 100 fps: 4194305 frames, one more than the limit (within 24 h). */
  clip = two_frames(0.0, 41943.04);
  if (clip != NULL) {
    expect_refused(clip, "c_hostile_many.vrma", 100.0, NULL, "4194304");
    avm_clip_destroy(clip);
  }
}

static void test_add_refuses_bad_times(void) {
  avm_clip* clip = NULL;
  avm_pose p;
  if (avm_clip_create(&clip) != AVM_OK) return;
  rest_pose(5.0, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_OK);
  rest_pose(1.0, &p); /* the last frame stamped before the first */
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(clip), "after the previous"));
  rest_pose(NAN, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT);
  rest_pose(INFINITY, &p);
  CHECK(avm_clip_add(clip, &p) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_frame_count(clip) == 1);
  avm_clip_destroy(clip);
}

int main(void) {
  test_huge_gaps();
  test_existing_file_kept();
  test_limits();
  test_add_refuses_bad_times();
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
