/* Capture through the C API: the estimator handle on a real photograph against Google's
 * reference landmarks for it (tfjs-models' pose.jpg, EXPECTED_LANDMARKS within EPSILON_IMAGE
 * pixels), bad images refused with a message (never a crash), and the live handle fed from a
 * second thread while the main thread samples. Needs $AVATARMAP_MODELS (the converted models),
 * $AVATARMAP_TEST_DATA and the ffmpeg command (to decode the JPEG): exits 77 (skipped) without
 * them. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "decode_image.h"
#include "test_util.h"

#define SKIP 77

/* Reads the 33 [x, y] pixel pairs of "pose-detection::EXPECTED_LANDMARKS" from the JSON file
 * of tfjs-models' expected values; 0 when they are not there. */
static int read_expected(const char* path, double xy[33][2]) {
  static char text[1 << 16];
  const char* key = "\"pose-detection::EXPECTED_LANDMARKS\"";
  size_t n;
  char* s;
  int i, k;
  FILE* f = fopen(path, "rb");
  if (f == NULL) return 0;
  n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = '\0';
  s = strstr(text, key);
  if (s == NULL) return 0;
  s += strlen(key);
  for (i = 0; i < 33; ++i)
    for (k = 0; k < 2; ++k) {
      char* end;
      while (*s != '\0' && !(*s == '-' || (*s >= '0' && *s <= '9'))) ++s;
      if (*s == '\0') return 0;
      xy[i][k] = strtod(s, &end);
      s = end;
    }
  return 1;
}

typedef struct pusher_args {
  avm_live* live;
  avm_image image;
  int frames;
  int failures;
} pusher_args;

/* The camera thread: pushes the same image as `frames` frames at 30 fps, 10 ms apart. */
static void* pusher(void* arg) {
  pusher_args* a = (pusher_args*)arg;
  int i;
  for (i = 0; i < a->frames; ++i) {
    if (avm_live_push(a->live, &a->image, i / 30.0) != AVM_OK) ++a->failures;
    sleep_ms(10);
  }
  return NULL;
}

int main(void) {
  const char* data = getenv("AVATARMAP_TEST_DATA");
  const char* models = getenv("AVATARMAP_MODELS");
  char image_path[1024], json_path[1024], err[256];
  const int width = 1000, height = 667; /* pose.jpg */
  double expected[33][2];
  unsigned char* px;
  avm_estimator_options eo;
  avm_estimator* est = NULL;
  avm_image image;
  avm_frame frame;
  avm_pose pose;
  int i, within = 0;
  double worst = 0.0;

  if (data == NULL || *data == '\0' || models == NULL || *models == '\0') {
    printf("skipped: set AVATARMAP_TEST_DATA and AVATARMAP_MODELS\n");
    return SKIP;
  }
  snprintf(image_path, sizeof image_path, "%s/motion/tfjs-models/pose.jpg", data);
  snprintf(json_path, sizeof json_path, "%s/motion/tfjs-models/expected_from_tests.json", data);
  if (!read_expected(json_path, expected)) {
    printf("skipped: no %s\n", json_path);
    return SKIP;
  }
  px = decode_rgb(image_path, width, height);
  if (px == NULL) {
    printf("skipped: the ffmpeg command could not decode %s\n", image_path);
    return SKIP;
  }

  /* Options: defaults, models from $AVATARMAP_MODELS; out-of-range fields refused. */
  CHECK(avm_estimator_options_init(&eo) == AVM_OK);
  if (avm_estimator_create(&eo, NULL, &est) == AVM_ERROR_UNSUPPORTED) {
    printf("skipped: %s\n", avm_last_create_error()); /* a build without ONNX Runtime */
    free(px);
    return SKIP;
  }
  avm_estimator_destroy(est);
  est = NULL;
  CHECK(eo.hands == 1 && eo.face == 1 && eo.model_complexity == 1 && eo.models_dir == NULL);
  eo.static_images = 1; /* one photograph */
  eo.threads = 0;
  CHECK(avm_estimator_create(&eo, NULL, &est) == AVM_ERROR_INVALID_ARGUMENT && est == NULL);
  CHECK(contains(avm_last_create_error(), "threads"));
  eo.threads = 2;
  eo.models_dir = "/nonexistent/models";
  CHECK(avm_estimator_create(&eo, NULL, &est) == AVM_ERROR_IO && est == NULL);
  CHECK(contains(avm_last_create_error(), "/nonexistent/models"));
  eo.models_dir = NULL;
  CHECK(avm_estimator_create(&eo, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_estimator_create(&eo, NULL, &est) == AVM_OK && est != NULL);
  if (est == NULL) {
    fprintf(stderr, "avm_estimator_create: %s\n", avm_last_create_error());
    free(px);
    return 1;
  }

  /* The photograph: Google's landmarks within tfjs-models' tolerance. */
  image.data = px;
  image.width = width;
  image.height = height;
  image.stride_bytes = width * 3;
  image.format = AVM_PIXEL_RGB8;
  memset(&frame, 0, sizeof frame);
  CHECK(avm_estimator_process(est, &image, 0.0, &frame, &pose) == AVM_OK);
  CHECK(frame.pose != NULL && frame.pose_world != NULL);
  if (frame.pose != NULL) {
    for (i = 0; i < 33; ++i) {
      const double dx = frame.pose[i].x * width - expected[i][0];
      const double dy = frame.pose[i].y * height - expected[i][1];
      const double d = fabs(dx) > fabs(dy) ? fabs(dx) : fabs(dy);
      if (d > worst) worst = d;
      within += d <= 11.0; /* EPSILON_IMAGE */
    }
    printf(
        "[figures] pose.jpg through avm_estimator_process: %d of 33 points within 11 px of "
        "Google's, worst coordinate %.1f px\n",
        within, worst);
    CHECK(within == 33);
  }
  CHECK(pose.t == 0.0);
  CHECK(pose.confidence[AVM_BONE_LEFT_UPPER_ARM] > 0.5f);
  /* The output frame's arrays belong to the estimator; NULL outputs are allowed. */
  CHECK(avm_estimator_process(est, &image, 1.0 / 30, NULL, NULL) == AVM_OK);

  /* Bad images: refused with a message, no crash, the estimator still works after. */
  {
    avm_image bad = image;
    bad.data = NULL;
    CHECK(avm_estimator_process(est, &bad, 0.1, &frame, &pose) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(avm_estimator_last_error(est), "no pixels"));
    bad = image;
    bad.width = 0;
    CHECK(avm_estimator_process(est, &bad, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    bad = image;
    bad.width = 100000;
    bad.height = 100000;
    CHECK(avm_estimator_process(est, &bad, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(avm_estimator_last_error(est), "16384"));
    bad = image;
    bad.stride_bytes = width * 3 - 1;
    CHECK(avm_estimator_process(est, &bad, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(avm_estimator_last_error(est), "stride_bytes"));
    bad = image;
    bad.format = 42;
    CHECK(avm_estimator_process(est, &bad, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(avm_estimator_last_error(est), "format"));
    CHECK(avm_estimator_process(est, NULL, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(avm_estimator_process(est, &image, NAN, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(avm_estimator_process(NULL, &image, 0.1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
    CHECK(avm_estimator_process(est, &image, 0.2, NULL, &pose) == AVM_OK);
    CHECK(strcmp(avm_estimator_last_error(est), "") == 0);
  }
  avm_estimator_destroy(est);
  avm_estimator_destroy(NULL);

  /* Live: a camera thread pushes, this thread samples meanwhile and after. */
  {
    avm_live* live = NULL;
    avm_live_stats st;
    pusher_args args;
    pthread_t thread;
    int polls = 0, posed = 0;
    eo.static_images = 0;
    CHECK(avm_live_create(&eo, NULL, &live) == AVM_OK && live != NULL);
    if (live != NULL) {
      CHECK(avm_live_sample(live, 0.0, &pose) == AVM_ERROR_END_OF_FILE); /* nothing yet */
      CHECK(pose.rotations[AVM_BONE_HIPS][3] == 1.f);
      args.live = live;
      args.image = image;
      args.frames = 20;
      args.failures = 0;
      CHECK(pthread_create(&thread, NULL, pusher, &args) == 0);
      for (polls = 0; polls < 200; ++polls) { /* the render thread, every 5 ms */
        if (avm_live_sample(live, polls * 0.005, &pose) == AVM_OK) ++posed;
        sleep_ms(5);
      }
      pthread_join(thread, NULL);
      CHECK(args.failures == 0);
      for (i = 0; i < 500; ++i) { /* let the worker finish */
        CHECK(avm_live_get_stats(live, &st) == AVM_OK);
        if (st.processed + st.dropped + st.failed >= st.pushed) break;
        sleep_ms(10);
      }
      printf(
          "[figures] live: %ld pushed, %ld processed, %ld dropped; latency p50 %.1f ms, "
          "p95 %.1f ms\n",
          (long)st.pushed, (long)st.processed, (long)st.dropped, st.latency_p50_ms,
          st.latency_p95_ms);
      CHECK(st.pushed == 20);
      CHECK(st.processed >= 1 && st.processed + st.dropped == 20 && st.failed == 0);
      CHECK(posed > 0);
      CHECK(avm_live_latest(live, &pose) == AVM_OK);
      CHECK(fabs(pose.t - 19 / 30.0) < 1e-9); /* the newest image is always processed */
      CHECK(avm_live_sample(live, 0.5, &pose) == AVM_OK && pose.t == 0.5);
      /* Bad pushes: refused, the message kept, nothing queued. */
      image.stride_bytes = 1;
      CHECK(avm_live_push(live, &image, 1.0) == AVM_ERROR_INVALID_ARGUMENT);
      CHECK(contains(avm_live_last_error(live, err, sizeof err), "stride_bytes"));
      CHECK(avm_live_push(live, NULL, 1.0) == AVM_ERROR_INVALID_ARGUMENT);
      CHECK(avm_live_get_stats(live, &st) == AVM_OK && st.pushed == 20);
      CHECK(avm_live_sample(live, NAN, &pose) == AVM_ERROR_INVALID_ARGUMENT);
      CHECK(avm_live_get_stats(NULL, &st) == AVM_ERROR_INVALID_ARGUMENT);
      avm_live_destroy(live);
    }
    avm_live_destroy(NULL);
  }
  free(px);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
