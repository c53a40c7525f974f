/* Several people through the C API (issue 25): tfjs-models' three_people.jpg through
 * avm_estimator_process_people and the live handle's avm_live_people / avm_live_sample_person
 * with max_people 3. The reference is the single-person estimator on the same image: the person
 * it follows must be one of the three, point for point (docs/capture-people.md: the person the
 * single-person capture follows goes through the same path). Bad arguments are refused, never a
 * crash. Needs $AVATARMAP_MODELS, $AVATARMAP_TEST_DATA and the ffmpeg command: exits 77
 * (skipped) without them. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "decode_image.h"
#include "test_util.h"

#define SKIP 77

/* 1 when the 33 body points of a and b are equal (x, y, z). */
static int same_body(const avm_landmark* a, const avm_landmark* b) {
  int i;
  if (a == NULL || b == NULL) return 0;
  for (i = 0; i < AVM_POSE_LANDMARK_COUNT; ++i)
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z) return 0;
  return 1;
}

/* Largest difference of two poses' rotation components. */
static double pose_difference(const avm_pose* a, const avm_pose* b) {
  double worst = 0.0;
  int k, c;
  for (k = 0; k < AVM_BONE_COUNT; ++k)
    for (c = 0; c < 4; ++c) {
      const double d = fabs((double)a->rotations[k][c] - (double)b->rotations[k][c]);
      if (d > worst) worst = d;
    }
  return worst;
}

int main(void) {
  const char* data = getenv("AVATARMAP_TEST_DATA");
  const char* models = getenv("AVATARMAP_MODELS");
  char image_path[1024];
  const int width = 1049, height = 861; /* three_people.jpg */
  unsigned char* px;
  avm_estimator_options eo;
  avm_estimator *single = NULL, *several = NULL;
  avm_live* live = NULL;
  avm_image image;
  avm_frame frame;
  avm_pose pose, sampled;
  avm_person people[AVM_MAX_PEOPLE];
  avm_live_person held[AVM_MAX_PEOPLE];
  avm_live_stats stats;
  int32_t count = -1, n = -1;
  int i, k, matches = 0, ids_seen = 0, slots_seen = 0;

  if (data == NULL || *data == '\0' || models == NULL || *models == '\0') {
    printf("skipped: set AVATARMAP_TEST_DATA and AVATARMAP_MODELS\n");
    return SKIP;
  }
  snprintf(image_path, sizeof image_path, "%s/motion/tfjs-models/three_people.jpg", data);
  px = decode_rgb(image_path, width, height);
  if (px == NULL) {
    printf("skipped: the ffmpeg command could not decode %s\n", image_path);
    return SKIP;
  }
  image.data = px;
  image.width = width;
  image.height = height;
  image.stride_bytes = width * 3;
  image.format = AVM_PIXEL_RGB8;

  CHECK(avm_estimator_options_init(&eo) == AVM_OK);
  CHECK(eo.max_people == 1);
  eo.static_images = 1; /* one photograph */
  if (avm_estimator_create(&eo, NULL, &single) == AVM_ERROR_UNSUPPORTED) {
    printf("skipped: %s\n", avm_last_create_error());
    free(px);
    return SKIP;
  }
  CHECK(single != NULL);
  eo.max_people = AVM_MAX_PEOPLE + 1;
  CHECK(avm_estimator_create(&eo, NULL, &several) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_last_create_error(), "max_people"));
  eo.max_people = 3;
  CHECK(avm_estimator_create(&eo, NULL, &several) == AVM_OK && several != NULL);

  /* The single-person reference, and the same call on the single-person handle (one person,
   * id 0, slot 0, the same landmarks). */
  CHECK(avm_estimator_process(single, &image, 0.0, &frame, &pose) == AVM_OK);
  CHECK(frame.pose != NULL);
  CHECK(avm_estimator_process_people(several, &image, 0.0, people, AVM_MAX_PEOPLE, &count) ==
        AVM_OK);
  printf("[figures] three_people.jpg through avm_estimator_process_people: %d people\n",
         (int)count);
  CHECK(count == 3);
  for (i = 0; i < count && i < AVM_MAX_PEOPLE; ++i) {
    CHECK(people[i].id >= 0 && people[i].id < 3);
    CHECK(people[i].slot >= 0 && people[i].slot < 3);
    ids_seen |= 1 << people[i].id;
    slots_seen |= 1 << people[i].slot;
    if (i > 0) CHECK(people[i - 1].id < people[i].id);
    CHECK(people[i].frame.pose != NULL && people[i].frame.face != NULL);
    matches += same_body(people[i].frame.pose, frame.pose);
    for (k = 0; k < i; ++k) CHECK(pose_difference(&people[i].pose, &people[k].pose) > 0.05);
  }
  CHECK(ids_seen == 7 && slots_seen == 7);
  CHECK(matches == 1); /* the single-person capture's person is one of them, exactly */

  /* A smaller buffer: the count is still every person; only `capacity` are written. */
  memset(people, 0xff, sizeof people);
  CHECK(avm_estimator_process_people(several, &image, 1.0, people, 1, &count) == AVM_OK);
  CHECK(count == 3 && people[0].id == 0 && people[1].id == -1);
  CHECK(avm_estimator_process_people(several, &image, 2.0, NULL, 0, &count) == AVM_OK);
  CHECK(count == 3);
  /* Bad arguments. */
  CHECK(avm_estimator_process_people(several, &image, 3.0, people, 3, NULL) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_estimator_last_error(several), "out_count"));
  CHECK(avm_estimator_process_people(several, &image, 3.0, people, -1, &count) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_estimator_process_people(several, &image, 3.0, NULL, 2, &count) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_estimator_process_people(several, NULL, 3.0, people, 3, &count) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_estimator_process_people(several, &image, NAN, people, 3, &count) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_estimator_process_people(NULL, &image, 3.0, people, 3, &count) ==
        AVM_ERROR_INVALID_ARGUMENT);
  /* The single-person handle: one person, id 0, slot 0, the landmarks of avm_estimator_process. */
  CHECK(avm_estimator_process_people(single, &image, 1.0, people, AVM_MAX_PEOPLE, &count) ==
        AVM_OK);
  CHECK(count == 1 && people[0].id == 0 && people[0].slot == 0);
  CHECK(count == 1 && same_body(people[0].frame.pose, frame.pose));

  /* The live handle: three people held, each sampled on its own. */
  CHECK(avm_live_create(&eo, NULL, &live) == AVM_OK && live != NULL);
  CHECK(avm_live_people(live, held, AVM_MAX_PEOPLE, &n) == AVM_OK && n == 0);
  for (i = 0; i < 3; ++i) {
    int waited = 0;
    CHECK(avm_live_push(live, &image, i / 30.0) == AVM_OK);
    do {
      sleep_ms(10);
      CHECK(avm_live_get_stats(live, &stats) == AVM_OK);
    } while (stats.processed + stats.dropped + stats.failed < i + 1 && ++waited < 2000);
  }
  CHECK(avm_live_people(live, held, AVM_MAX_PEOPLE, &n) == AVM_OK);
  CHECK(n == 3);
  for (i = 0; i < n && i < AVM_MAX_PEOPLE; ++i) {
    CHECK(avm_live_sample_person(live, held[i].id, 2 / 30.0, &sampled) == AVM_OK);
    CHECK(held[i].seen_t == 2 / 30.0);
    if (i > 0) CHECK(held[i - 1].id < held[i].id);
  }
  CHECK(avm_live_sample_person(live, 1000, 2 / 30.0, &sampled) == AVM_ERROR_END_OF_FILE);
  CHECK(sampled.rotations[0][3] == 1.f); /* the rest pose */
  CHECK(avm_live_people(live, NULL, 0, &n) == AVM_OK && n == 3);
  CHECK(avm_live_people(live, held, -1, &n) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_live_people(live, held, 3, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_live_sample_person(live, 0, NAN, &sampled) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_live_sample_person(live, 0, 0.0, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  avm_live_destroy(live);
  CHECK(avm_live_people(live, held, 3, &n) == AVM_ERROR_INVALID_ARGUMENT); /* destroyed */

  avm_estimator_destroy(single);
  avm_estimator_destroy(several);
  free(px);
  return check_exit();
}
