/* Tests of the C API (bindings/c/include/avatarmap/avatarmap.h), written in C99.
 * One process, one check macro; every failure prints its line and the test exits 1. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"

static int g_failures = 0;

#define CHECK(cond)                                                            \
  do {                                                                         \
    if (!(cond)) {                                                             \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
      ++g_failures;                                                            \
    }                                                                          \
  } while (0)

#define CHECK_STATUS(expr, expected)                                                     \
  do {                                                                                   \
    avm_status st_ = (expr);                                                             \
    if (st_ != (expected)) {                                                             \
      fprintf(stderr, "%s:%d: %s returned %s, expected %s\n", __FILE__, __LINE__, #expr, \
              avm_status_string(st_), avm_status_string(expected));                      \
      ++g_failures;                                                                      \
    }                                                                                    \
  } while (0)

/* ---- a hand-built T-pose ------------------------------------------------------------- */

/* MediaPipe world coordinates (metres, origin at the hip midpoint, x toward image right,
 * y down, z away from the camera) of a person facing a non-mirrored camera in a T-pose: the
 * person's left (odd indices) is at +x. */
static const float k_tpose_world[AVM_POSE_LANDMARK_COUNT][3] = {
    {0.f, -0.62f, -0.10f},                                                           /* 0 nose */
    {0.015f, -0.65f, -0.08f},  {0.03f, -0.65f, -0.08f},   {0.045f, -0.65f, -0.07f},  /* 1-3 */
    {-0.015f, -0.65f, -0.08f}, {-0.03f, -0.65f, -0.08f},  {-0.045f, -0.65f, -0.07f}, /* 4-6 */
    {0.075f, -0.63f, 0.f},     {-0.075f, -0.63f, 0.f},                               /* 7, 8 ears */
    {0.025f, -0.57f, -0.09f},  {-0.025f, -0.57f, -0.09f}, /* 9, 10 mouth */
    {0.18f, -0.50f, 0.f},      {-0.18f, -0.50f, 0.f},     /* 11, 12 shoulders */
    {0.45f, -0.50f, 0.f},      {-0.45f, -0.50f, 0.f},     /* 13, 14 elbows */
    {0.70f, -0.50f, 0.f},      {-0.70f, -0.50f, 0.f},     /* 15, 16 wrists */
    {0.78f, -0.50f, 0.03f},    {-0.78f, -0.50f, 0.03f},   /* 17, 18 pinky */
    {0.80f, -0.50f, -0.02f},   {-0.80f, -0.50f, -0.02f},  /* 19, 20 index */
    {0.75f, -0.50f, -0.05f},   {-0.75f, -0.50f, -0.05f},  /* 21, 22 thumb */
    {0.10f, 0.f, 0.f},         {-0.10f, 0.f, 0.f},        /* 23, 24 hips */
    {0.10f, 0.45f, 0.f},       {-0.10f, 0.45f, 0.f},      /* 25, 26 knees */
    {0.10f, 0.88f, 0.f},       {-0.10f, 0.88f, 0.f},      /* 27, 28 ankles */
    {0.10f, 0.92f, 0.05f},     {-0.10f, 0.92f, 0.05f},    /* 29, 30 heels */
    {0.10f, 0.95f, -0.12f},    {-0.10f, 0.95f, -0.12f}};  /* 31, 32 toes */

typedef struct test_frame {
  avm_landmark pose[AVM_POSE_LANDMARK_COUNT];
  avm_landmark pose_world[AVM_POSE_LANDMARK_COUNT];
  avm_frame frame;
} test_frame;

/* Fills `f` with the T-pose at time t; `arm_drop` (radians) swings the person's left arm down
 * about the shoulder, toward the side. Image points are the world points scaled into a
 * square image. */
static void make_tpose(test_frame* f, double t, float arm_drop) {
  int i;
  for (i = 0; i < AVM_POSE_LANDMARK_COUNT; ++i) {
    float x = k_tpose_world[i][0], y = k_tpose_world[i][1], z = k_tpose_world[i][2];
    if (arm_drop != 0.f && (i == 13 || i == 15 || i == 17 || i == 19 || i == 21)) {
      float dx = x - 0.18f, dy = y + 0.50f; /* relative to the left shoulder */
      float c = cosf(arm_drop), s = sinf(arm_drop);
      x = 0.18f + c * dx - s * dy;
      y = -0.50f + s * dx + c * dy; /* y down: positive angle lowers the arm */
    }
    f->pose_world[i].x = x;
    f->pose_world[i].y = y;
    f->pose_world[i].z = z;
    f->pose_world[i].visibility = 0.99f;
    f->pose_world[i].presence = 0.99f;
    f->pose[i].x = 0.5f + 0.4f * x;
    f->pose[i].y = 0.5f + 0.4f * y;
    f->pose[i].z = 0.4f * z;
    f->pose[i].visibility = 0.99f;
    f->pose[i].presence = 0.99f;
  }
  memset(&f->frame, 0, sizeof f->frame);
  f->frame.t = t;
  f->frame.pose = f->pose;
  f->frame.pose_world = f->pose_world;
}

/* ---- helpers ------------------------------------------------------------------------- */

static int pose_is_finite(const avm_pose* p) {
  int b, k;
  if (!isfinite(p->t)) return 0;
  for (k = 0; k < 3; ++k)
    if (!isfinite(p->hips_position[k])) return 0;
  for (b = 0; b < AVM_BONE_COUNT; ++b) {
    for (k = 0; k < 4; ++k)
      if (!isfinite(p->rotations[b][k])) return 0;
    if (!isfinite(p->confidence[b])) return 0;
  }
  for (k = 0; k < AVM_EXPRESSION_COUNT; ++k)
    if (!isfinite(p->expressions[k])) return 0;
  for (k = 0; k < AVM_BLENDSHAPE_COUNT; ++k)
    if (!isfinite(p->blendshapes[k])) return 0;
  for (k = 0; k < 2; ++k)
    if (!isfinite(p->foot_contact[k])) return 0;
  return 1;
}

static int rotations_are_unit(const avm_pose* p) {
  int b;
  for (b = 0; b < AVM_BONE_COUNT; ++b) {
    const float* q = p->rotations[b];
    double n =
        sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    if (fabs(n - 1.0) > 1e-3) return 0;
  }
  return 1;
}

/* Angle in radians between two {x, y, z, w} rotations (q and -q are the same rotation). */
static double quat_angle(const float* a, const float* b) {
  double d =
      fabs((double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3]);
  if (d > 1.0) d = 1.0;
  return 2.0 * acos(d);
}

static avm_solver* make_solver(void) {
  avm_solver* s = NULL;
  CHECK_STATUS(avm_solver_create(NULL, &s), AVM_OK);
  CHECK(s != NULL);
  return s;
}

/* ---- tests --------------------------------------------------------------------------- */

static void test_version(void) {
  int major = -1, minor = -1, patch = -1;
  char expected[64];
  avm_version(&major, &minor, &patch);
  CHECK(major == AVM_VERSION_MAJOR);
  CHECK(minor == AVM_VERSION_MINOR);
  CHECK(patch == AVM_VERSION_PATCH);
  avm_version(NULL, NULL, NULL); /* must not crash */
  sprintf(expected, "%d.%d.%d", AVM_VERSION_MAJOR, AVM_VERSION_MINOR, AVM_VERSION_PATCH);
  CHECK(strcmp(avm_version_string(), expected) == 0);
  CHECK(strcmp(avm_version_string(), AVM_VERSION_STRING) == 0);
  CHECK(AVM_VERSION_NUMBER == major * 10000 + minor * 100 + patch);
}

static void test_status_strings(void) {
  int s;
  CHECK(strcmp(avm_status_string(AVM_OK), "ok") == 0);
  for (s = AVM_OK; s <= AVM_ERROR_INTERNAL; ++s) {
    const char* text = avm_status_string((avm_status)s);
    CHECK(text != NULL && text[0] != '\0');
    CHECK(strcmp(text, "unknown status") != 0);
  }
  CHECK(strcmp(avm_status_string((avm_status)999), "unknown status") == 0);
}

static void test_create_destroy(void) {
  avm_solver* s = NULL;
  avm_solver_options o;
  CHECK_STATUS(avm_solver_create(NULL, &s), AVM_OK);
  CHECK(s != NULL);
  CHECK(strcmp(avm_solver_last_error(s), "") == 0);
  CHECK(strcmp(avm_last_create_error(), "") == 0);
  avm_solver_destroy(s);

  CHECK_STATUS(avm_solver_options_init(&o), AVM_OK);
  CHECK(o.struct_size == sizeof o);
  CHECK(o.solve_body == 1 && o.filter_rotations == 1);
  CHECK(o.hips_lean_share >= 0.f && o.hips_lean_share <= 1.f);
  s = NULL;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_OK);
  CHECK(s != NULL);
  CHECK_STATUS(avm_solver_reset(s), AVM_OK);
  avm_solver_destroy(s);

  avm_solver_destroy(NULL); /* no-op */
}

static void test_null_arguments(void) {
  avm_solver* s = make_solver();
  test_frame f;
  avm_pose pose;
  make_tpose(&f, 0.0, 0.f);

  CHECK_STATUS(avm_solver_options_init(NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_create(NULL, NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_last_create_error()[0] != '\0');
  CHECK_STATUS(avm_solver_reset(NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_push(NULL, &f.frame), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_push(s, NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_solver_last_error(s), "NULL") != NULL);
  CHECK_STATUS(avm_solver_get_pose(NULL, &pose), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_get_pose(s, NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_sample(NULL, 0.0, &pose), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_sample(s, 0.0, NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_sample(s, NAN, &pose), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strcmp(avm_solver_last_error(NULL), "") == 0);
  CHECK_STATUS(avm_solve_file(NULL, "x.pose.jsonl", NULL, NULL, 0), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solve_file("x.landmarks.jsonl", NULL, NULL, NULL, 0),
               AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_bone_name(-1) == NULL && avm_bone_name(AVM_BONE_COUNT) == NULL);
  CHECK(avm_bone_from_name(NULL) == -1);
  CHECK(avm_expression_name(AVM_EXPRESSION_COUNT) == NULL);
  CHECK(avm_expression_from_name(NULL) == -1);

  /* A successful call clears the handle's message. */
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  CHECK(strcmp(avm_solver_last_error(s), "") == 0);
  avm_solver_destroy(s);
}

static void test_invalid_options(void) {
  avm_solver_options o;
  avm_solver* s = (avm_solver*)&o; /* any non-NULL value: must be overwritten with NULL */

  avm_solver_options_init(&o);
  o.hips_lean_share = 2.f;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(s == NULL);
  CHECK(strstr(avm_last_create_error(), "hips_lean_share") != NULL);

  avm_solver_options_init(&o);
  o.rotation_min_cutoff = 0.f;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_last_create_error(), "rotation_min_cutoff") != NULL);

  avm_solver_options_init(&o);
  o.image_width = 640.f; /* width without height */
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_last_create_error(), "image_width") != NULL);

  avm_solver_options_init(&o);
  o.max_extrapolation_seconds = -1.f;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_last_create_error(), "max_extrapolation_seconds") != NULL);

  avm_solver_options_init(&o);
  o.struct_size = 0; /* not initialised */
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_last_create_error(), "struct_size") != NULL);

  /* A successful create clears the thread's message. */
  CHECK_STATUS(avm_solver_create(NULL, &s), AVM_OK);
  CHECK(strcmp(avm_last_create_error(), "") == 0);
  avm_solver_destroy(s);
}

static void test_struct_size_evolution(void) {
  avm_solver_options o;
  avm_solver* s = NULL;
  struct newer {
    avm_solver_options known;
    uint32_t future_fields[8];
  } n;

  /* An older caller that knows only the fields before the filter settings: the garbage
   * after its struct must not be read; defaults are used instead. */
  avm_solver_options_init(&o);
  o.rotation_min_cutoff = -5.f; /* would be invalid if read */
  o.struct_size = (uint32_t)offsetof(avm_solver_options, filter_rotations);
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_OK);
  avm_solver_destroy(s);
  s = NULL;

  /* ... but the fields it has are read. */
  o.hips_lean_share = -1.f;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_ERROR_INVALID_ARGUMENT);

  /* A newer caller with more fields: the known prefix is used. */
  memset(&n, 0xff, sizeof n);
  avm_solver_options_init(&n.known);
  n.known.struct_size = (uint32_t)sizeof n;
  CHECK_STATUS(avm_solver_create(&n.known, &s), AVM_OK);
  avm_solver_destroy(s);
  s = NULL;
}

/* Initialising never writes past the caller's struct: an older caller's (shorter) struct is
 * filled up to its size only, a newer caller's fields past this library's are left alone. */
static void test_sized_init(void) {
  const size_t older = offsetof(avm_solver_options, filter_rotations);
  union {
    avm_solver_options o;
    unsigned char bytes[sizeof(avm_solver_options) + 32];
  } u;
  avm_estimator_options eo;
  avm_solver* s = NULL;
  size_t i;
  int untouched = 1;

  memset(&u, 0xab, sizeof u);
  CHECK_STATUS(avm_solver_options_init_sized(&u.o, older), AVM_OK);
  CHECK(u.o.struct_size == (uint32_t)older);
  CHECK(u.o.solve_body == 1 && u.o.confidence_found_above == 0.5f);
  for (i = older; i < sizeof u.bytes; ++i) untouched &= u.bytes[i] == 0xab;
  CHECK(untouched);
  CHECK_STATUS(avm_solver_create(&u.o, &s), AVM_OK); /* the rest are the library's defaults */
  avm_solver_destroy(s);
  s = NULL;

  memset(&u, 0xab, sizeof u);
  CHECK_STATUS(avm_solver_options_init_sized(&u.o, sizeof u.bytes), AVM_OK);
  CHECK(u.o.struct_size == (uint32_t)sizeof u.bytes && u.o.file_threads == 2);
  untouched = 1;
  for (i = sizeof(avm_solver_options); i < sizeof u.bytes; ++i) untouched &= u.bytes[i] == 0xab;
  CHECK(untouched);

  /* The macro is the sized form with this header's struct. */
  memset(&u, 0, sizeof u);
  CHECK_STATUS(avm_solver_options_init(&u.o), AVM_OK);
  CHECK(u.o.struct_size == (uint32_t)sizeof(avm_solver_options));
  CHECK_STATUS((avm_solver_options_init)(&u.o), AVM_OK); /* the function, for old binaries */
  CHECK(u.o.struct_size == (uint32_t)sizeof(avm_solver_options));

  CHECK_STATUS(avm_solver_options_init_sized(NULL, sizeof u.o), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_options_init_sized(&u.o, 4), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_options_init_sized(&u.o, 4097), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_solver_options_init_sized(&u.o, 10), AVM_ERROR_INVALID_ARGUMENT);

  CHECK_STATUS(avm_estimator_options_init(&eo), AVM_OK);
  CHECK(eo.struct_size == (uint32_t)sizeof eo && eo.hands == 1 && eo.threads == 2);
  CHECK_STATUS(avm_estimator_options_init_sized(&eo, 4), AVM_ERROR_INVALID_ARGUMENT);
  CHECK_STATUS(avm_estimator_options_init_sized(NULL, sizeof eo), AVM_ERROR_INVALID_ARGUMENT);
}

static void test_bad_frames(void) {
  avm_solver* s = make_solver();
  test_frame f;
  avm_landmark face[AVM_FACE_IRIS_LANDMARK_COUNT];
  memset(face, 0, sizeof face);
  make_tpose(&f, 0.0, 0.f);

  f.frame.face = face;
  f.frame.face_count = 100;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_solver_last_error(s), "face_count") != NULL);
  f.frame.face_count = 0;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_ERROR_INVALID_ARGUMENT);

  f.frame.face_count = AVM_FACE_LANDMARK_COUNT;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  CHECK(strcmp(avm_solver_last_error(s), "") == 0);
  f.frame.t = 0.1;
  f.frame.face_count = AVM_FACE_IRIS_LANDMARK_COUNT;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);

  /* face NULL: face_count is ignored. */
  f.frame.t = 0.2;
  f.frame.face = NULL;
  f.frame.face_count = -7;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);

  f.frame.t = NAN;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(avm_solver_last_error(s), "t must be finite") != NULL);
  avm_solver_destroy(s);
}

static void test_rest_pose(void) {
  avm_solver* s = make_solver();
  test_frame f;
  avm_pose pose;
  int i;

  /* Before any push: the rest pose. */
  CHECK_STATUS(avm_solver_get_pose(s, &pose), AVM_OK);
  CHECK(pose_is_finite(&pose));
  CHECK(pose.rotations[AVM_BONE_HIPS][3] == 1.f);

  for (i = 0; i < 5; ++i) {
    make_tpose(&f, 0.1 * i, 0.f);
    CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  }
  CHECK_STATUS(avm_solver_get_pose(s, &pose), AVM_OK);
  CHECK(fabs(pose.t - 0.4) < 1e-9);
  CHECK(pose_is_finite(&pose));
  CHECK(rotations_are_unit(&pose));
  /* A T-pose is the VRM rest pose: the arms and legs must be near identity ({0,0,0,1}, w
   * last: this also checks the component order). Loose bounds: the input is hand-built. */
  {
    static const int bones[] = {AVM_BONE_HIPS, AVM_BONE_LEFT_UPPER_ARM, AVM_BONE_RIGHT_UPPER_ARM,
                                AVM_BONE_LEFT_LOWER_ARM, AVM_BONE_LEFT_UPPER_LEG};
    static const float identity[4] = {0.f, 0.f, 0.f, 1.f};
    size_t k;
    for (k = 0; k < sizeof bones / sizeof bones[0]; ++k) {
      double a = quat_angle(pose.rotations[bones[k]], identity);
      if (a > 0.5) fprintf(stderr, "%s is %.3f rad from rest\n", avm_bone_name(bones[k]), a);
      CHECK(a < 0.5);
    }
  }
  CHECK(pose.confidence[AVM_BONE_LEFT_UPPER_ARM] > 0.f);
  CHECK(pose.hips_position[1] > 0.f);
  avm_solver_destroy(s);
}

static void test_nan_frame(void) {
  avm_solver* s = make_solver();
  test_frame f;
  avm_landmark hand[AVM_HAND_LANDMARK_COUNT];
  avm_landmark face[AVM_FACE_IRIS_LANDMARK_COUNT];
  avm_pose pose;
  int i;
  make_tpose(&f, 0.0, 0.f);
  for (i = 0; i < AVM_POSE_LANDMARK_COUNT; ++i) {
    f.pose[i].x = f.pose[i].y = f.pose[i].z = NAN;
    f.pose[i].visibility = f.pose[i].presence = NAN;
    f.pose_world[i] = f.pose[i];
  }
  for (i = 0; i < AVM_HAND_LANDMARK_COUNT; ++i) {
    hand[i].x = hand[i].y = hand[i].z = NAN;
    hand[i].visibility = hand[i].presence = INFINITY;
  }
  for (i = 0; i < AVM_FACE_IRIS_LANDMARK_COUNT; ++i) {
    face[i].x = face[i].y = face[i].z = -INFINITY;
    face[i].visibility = face[i].presence = 1.f;
  }
  f.frame.left_hand = f.frame.left_hand_world = hand;
  f.frame.right_hand = f.frame.right_hand_world = hand;
  f.frame.face = face;
  f.frame.face_count = AVM_FACE_IRIS_LANDMARK_COUNT;
  for (i = 0; i < 3; ++i) {
    f.frame.t = 0.1 * i;
    CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
    CHECK_STATUS(avm_solver_get_pose(s, &pose), AVM_OK);
    CHECK(pose_is_finite(&pose));
    CHECK(rotations_are_unit(&pose));
  }
  CHECK_STATUS(avm_solver_sample(s, 0.15, &pose), AVM_OK);
  CHECK(pose_is_finite(&pose));

  /* Seen, then NaN: still finite. */
  make_tpose(&f, 1.0, 0.f);
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  f.pose_world[15].x = NAN;
  f.pose[13].y = NAN;
  f.frame.t = 1.1;
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  CHECK_STATUS(avm_solver_get_pose(s, &pose), AVM_OK);
  CHECK(pose_is_finite(&pose));
  CHECK(rotations_are_unit(&pose));
  avm_solver_destroy(s);
}

static void test_bones_and_expressions(void) {
  int b, e;
  CHECK(strcmp(avm_bone_name(AVM_BONE_HIPS), "hips") == 0);
  CHECK(strcmp(avm_bone_name(AVM_BONE_LEFT_UPPER_ARM), "leftUpperArm") == 0);
  CHECK(strcmp(avm_bone_name(AVM_BONE_RIGHT_LITTLE_DISTAL), "rightLittleDistal") == 0);
  CHECK(avm_bone_parent(AVM_BONE_HIPS) == -1);
  CHECK(avm_bone_parent(AVM_BONE_SPINE) == AVM_BONE_HIPS);
  CHECK(avm_bone_parent(AVM_BONE_LEFT_LOWER_ARM) == AVM_BONE_LEFT_UPPER_ARM);
  CHECK(avm_bone_parent(AVM_BONE_LEFT_SHOULDER) == AVM_BONE_UPPER_CHEST);
  CHECK(avm_bone_parent(AVM_BONE_RIGHT_INDEX_PROXIMAL) == AVM_BONE_RIGHT_HAND);
  CHECK(avm_bone_parent(AVM_BONE_COUNT) == -1 && avm_bone_parent(-3) == -1);
  CHECK(avm_bone_from_name("leftUpperLeg") == AVM_BONE_LEFT_UPPER_LEG);
  CHECK(avm_bone_from_name("LeftUpperLeg") == -1); /* case-sensitive */
  CHECK(avm_bone_from_name("") == -1);
  for (b = 0; b < AVM_BONE_COUNT; ++b) {
    const char* name = avm_bone_name(b);
    CHECK(name != NULL);
    CHECK(avm_bone_from_name(name) == b);
    CHECK(avm_bone_parent(b) < b); /* parents come first */
  }
  CHECK(strcmp(avm_expression_name(AVM_EXPRESSION_BLINK_LEFT), "blinkLeft") == 0);
  CHECK(strcmp(avm_expression_name(AVM_EXPRESSION_AA), "aa") == 0);
  CHECK(avm_expression_from_name("browDownRight") == AVM_EXPRESSION_BROW_DOWN_RIGHT);
  CHECK(avm_expression_from_name("nope") == -1);
  for (e = 0; e < AVM_EXPRESSION_COUNT; ++e) {
    CHECK(avm_expression_name(e) != NULL);
    CHECK(avm_expression_from_name(avm_expression_name(e)) == e);
  }
  CHECK(strcmp(avm_expression_name(AVM_EXPRESSION_HAPPY), "happy") == 0);
  CHECK(strcmp(avm_expression_name(AVM_EXPRESSION_SURPRISED), "surprised") == 0);
  CHECK(avm_expression_from_name("relaxed") == AVM_EXPRESSION_RELAXED);
  CHECK(avm_expression_from_name("angry") == AVM_EXPRESSION_ANGRY);
  CHECK(avm_expression_from_name("sad") == AVM_EXPRESSION_SAD);
}

/* ARKit's names, in Apple's alphabetical order (ARFaceAnchor.BlendShapeLocation). */
static void test_blendshapes(void) {
  int s;
  CHECK(strcmp(avm_blendshape_name(AVM_BLENDSHAPE_BROW_DOWN_LEFT), "browDownLeft") == 0);
  CHECK(strcmp(avm_blendshape_name(AVM_BLENDSHAPE_EYE_BLINK_RIGHT), "eyeBlinkRight") == 0);
  CHECK(strcmp(avm_blendshape_name(AVM_BLENDSHAPE_JAW_OPEN), "jawOpen") == 0);
  CHECK(strcmp(avm_blendshape_name(AVM_BLENDSHAPE_MOUTH_SMILE_LEFT), "mouthSmileLeft") == 0);
  CHECK(strcmp(avm_blendshape_name(AVM_BLENDSHAPE_TONGUE_OUT), "tongueOut") == 0);
  CHECK(avm_blendshape_name(AVM_BLENDSHAPE_COUNT) == NULL && avm_blendshape_name(-1) == NULL);
  CHECK(avm_blendshape_from_name("cheekPuff") == AVM_BLENDSHAPE_CHEEK_PUFF);
  CHECK(avm_blendshape_from_name("CheekPuff") == -1); /* case-sensitive */
  CHECK(avm_blendshape_from_name("_neutral") == -1);  /* MediaPipe's extra, not ARKit's */
  CHECK(avm_blendshape_from_name("") == -1 && avm_blendshape_from_name(NULL) == -1);
  for (s = 0; s < AVM_BLENDSHAPE_COUNT; ++s) {
    const char* name = avm_blendshape_name(s);
    CHECK(name != NULL);
    CHECK(avm_blendshape_from_name(name) == s);
    if (s > 0 && name != NULL) CHECK(strcmp(avm_blendshape_name(s - 1), name) < 0);
  }
}

static void test_sample_between_pushes(void) {
  avm_solver_options o;
  avm_solver* s = NULL;
  test_frame f;
  avm_pose a, b, mid, before, after;
  int bone;
  double max_err = 0.0;

  avm_solver_options_init(&o);
  o.filter_rotations = o.filter_position = o.filter_expressions = 0;
  CHECK_STATUS(avm_solver_create(&o, &s), AVM_OK);
  if (s == NULL) return;

  /* Nothing pushed yet: the rest pose at the requested time. */
  CHECK_STATUS(avm_solver_sample(s, 3.0, &mid), AVM_OK);
  CHECK(mid.t == 3.0 && mid.rotations[AVM_BONE_LEFT_UPPER_ARM][3] == 1.f);

  make_tpose(&f, 1.0, 0.f);
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  CHECK_STATUS(avm_solver_get_pose(s, &a), AVM_OK);
  make_tpose(&f, 1.1, 1.0f); /* left arm ~57 degrees down */
  CHECK_STATUS(avm_solver_push(s, &f.frame), AVM_OK);
  CHECK_STATUS(avm_solver_get_pose(s, &b), AVM_OK);

  CHECK(quat_angle(a.rotations[AVM_BONE_LEFT_UPPER_ARM], b.rotations[AVM_BONE_LEFT_UPPER_ARM]) >
        0.5);

  CHECK_STATUS(avm_solver_sample(s, 1.05, &mid), AVM_OK);
  CHECK(mid.t == 1.05);
  CHECK(pose_is_finite(&mid));
  CHECK(rotations_are_unit(&mid));
  /* Slerp halfway: every bone is equally far from both neighbours, at half their distance. */
  for (bone = 0; bone < AVM_BONE_COUNT; ++bone) {
    double ab = quat_angle(a.rotations[bone], b.rotations[bone]);
    double am = quat_angle(a.rotations[bone], mid.rotations[bone]);
    double mb = quat_angle(mid.rotations[bone], b.rotations[bone]);
    double err = fabs(am - 0.5 * ab) + fabs(mb - 0.5 * ab);
    if (err > max_err) max_err = err;
  }
  CHECK(max_err < 2e-3);
  {
    int k;
    for (k = 0; k < 3; ++k)
      CHECK(fabs(mid.hips_position[k] - 0.5f * (a.hips_position[k] + b.hips_position[k])) < 1e-4);
  }

  /* Before the first frame: held at the first; long after the last: finite (extrapolation is
   * bounded). */
  CHECK_STATUS(avm_solver_sample(s, 0.0, &before), AVM_OK);
  CHECK(quat_angle(before.rotations[AVM_BONE_LEFT_UPPER_ARM],
                   a.rotations[AVM_BONE_LEFT_UPPER_ARM]) < 1e-3);
  CHECK_STATUS(avm_solver_sample(s, 100.0, &after), AVM_OK);
  CHECK(pose_is_finite(&after) && rotations_are_unit(&after));

  /* reset forgets the frames. */
  CHECK_STATUS(avm_solver_reset(s), AVM_OK);
  CHECK_STATUS(avm_solver_get_pose(s, &mid), AVM_OK);
  CHECK(mid.rotations[AVM_BONE_LEFT_UPPER_ARM][3] == 1.f);
  avm_solver_destroy(s);
}

/* Writes the landmark file of three T-pose frames (REFERENCE §3). */
static int write_landmark_file(const char* path) {
  FILE* fp = fopen(path, "w");
  int frame, i;
  test_frame f;
  if (fp == NULL) return 0;
  fprintf(fp,
          "{\"format\":\"avatarmap.landmarks\",\"version\":1,\"image_size\":[640,480],"
          "\"fps\":10}\n");
  for (frame = 0; frame < 3; ++frame) {
    make_tpose(&f, 0.1 * frame, 0.2f * (float)frame);
    fprintf(fp, "{\"t\":%.3f,\"pose\":[", 0.1 * frame);
    for (i = 0; i < AVM_POSE_LANDMARK_COUNT; ++i)
      fprintf(fp, "%s[%g,%g,%g,%g,%g]", i ? "," : "", f.pose[i].x, f.pose[i].y, f.pose[i].z,
              f.pose[i].visibility, f.pose[i].presence);
    fprintf(fp, "],\"pose_world\":[");
    for (i = 0; i < AVM_POSE_LANDMARK_COUNT; ++i)
      fprintf(fp, "%s[%g,%g,%g,%g,%g]", i ? "," : "", f.pose_world[i].x, f.pose_world[i].y,
              f.pose_world[i].z, f.pose_world[i].visibility, f.pose_world[i].presence);
    fprintf(fp, "]}\n");
  }
  return fclose(fp) == 0;
}

/* Number of lines of a file, -1 when it cannot be opened; sets *has_hips when a line names
 * the hips bone. */
static int count_lines(const char* path, int* has_hips) {
  char line[65536];
  int n = 0;
  FILE* fp = fopen(path, "r");
  if (fp == NULL) return -1;
  *has_hips = 0;
  while (fgets(line, sizeof line, fp) != NULL) {
    ++n;
    if (strstr(line, "\"hips\"") != NULL) *has_hips = 1;
  }
  fclose(fp);
  return n;
}

/* The whole file as a NUL-terminated string (malloc'd), or NULL. */
static char* read_text(const char* path) {
  FILE* fp = fopen(path, "rb");
  char* buf = NULL;
  long n;
  if (fp == NULL) return NULL;
  if (fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) >= 0 && fseek(fp, 0, SEEK_SET) == 0) {
    buf = (char*)malloc((size_t)n + 1);
    if (buf != NULL) buf[fread(buf, 1, (size_t)n, fp)] = '\0';
  }
  fclose(fp);
  return buf;
}

static void test_solve_file(void) {
  const char* in = "c_api_test_input.landmarks.jsonl";
  const char* out = "c_api_test_output.pose.jsonl";
  const char* bad = "c_api_test_bad.landmarks.jsonl";
  char err[256];
  int has_hips = 0, lines;
  FILE* fp;
  avm_solver_options o;

  remove(out);
  CHECK(write_landmark_file(in));
  memset(err, 'x', sizeof err);
  CHECK_STATUS(avm_solve_file(in, out, NULL, err, sizeof err), AVM_OK);
  CHECK(err[0] == '\0');
  if (err[0] != '\0') fprintf(stderr, "avm_solve_file: %s\n", err);
  lines = count_lines(out, &has_hips);
  CHECK(lines >= 3); /* three frames (+ an optional header) */
  CHECK(has_hips);

  /* Options are checked. */
  avm_solver_options_init(&o);
  o.horizontal_fov_degrees = 500.f;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(err, "horizontal_fov_degrees") != NULL);

  /* Files are smoothed offline (zero lag) by default; the mode and strength are checked. */
  avm_solver_options_init(&o);
  CHECK(o.file_filter == AVM_FILE_FILTER_OFFLINE);
  CHECK(o.file_smoothing == 1.f);
  o.file_filter = 7;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(err, "file_filter") != NULL);
  avm_solver_options_init(&o);
  o.file_smoothing = -1.f;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(err, "file_smoothing") != NULL);
  avm_solver_options_init(&o);
  o.file_filter = AVM_FILE_FILTER_LIVE;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_OK);
  CHECK(count_lines(out, &has_hips) == lines);
  o.file_filter = AVM_FILE_FILTER_NONE;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_OK);
  CHECK(count_lines(out, &has_hips) == lines);

  /* file_threads: 2 (parse ahead) by default; 1 writes the same bytes; others are refused. */
  avm_solver_options_init(&o);
  CHECK(o.file_threads == 2);
  CHECK(o.fit_hand_shape == 1); /* the hands fitted to their learnt shape by default */
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_OK);
  {
    char* two = read_text(out);
    char* one;
    o.file_threads = 1;
    CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_OK);
    one = read_text(out);
    CHECK(one != NULL && two != NULL && strlen(one) > 100 && strcmp(one, two) == 0);
    free(one);
    free(two);
  }
  o.file_threads = 3;
  CHECK_STATUS(avm_solve_file(in, out, &o, err, sizeof err), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(strstr(err, "file_threads") != NULL);

  /* A missing input: an I/O error with a message; the output is untouched. */
  CHECK_STATUS(avm_solve_file("does/not/exist.landmarks.jsonl", out, NULL, err, sizeof err),
               AVM_ERROR_IO);
  CHECK(err[0] != '\0');
  CHECK(count_lines(out, &has_hips) == lines);

  /* A malformed line: a parse error naming the line; the output is untouched. */
  fp = fopen(bad, "w");
  CHECK(fp != NULL);
  if (fp != NULL) {
    fprintf(fp, "{\"t\":0.0}\n{\"t\": [oops\n");
    fclose(fp);
  }
  CHECK_STATUS(avm_solve_file(bad, out, NULL, err, sizeof err), AVM_ERROR_PARSE);
  CHECK(strstr(err, ":2") != NULL);
  if (strstr(err, ":2") == NULL) fprintf(stderr, "parse error message: %s\n", err);
  CHECK(count_lines(out, &has_hips) == lines);

  /* A tiny error buffer is still NUL-terminated; NULL / 0 are accepted. */
  err[0] = 'x';
  CHECK_STATUS(avm_solve_file("missing.landmarks.jsonl", out, NULL, err, 1), AVM_ERROR_IO);
  CHECK(err[0] == '\0');
  CHECK_STATUS(avm_solve_file("missing.landmarks.jsonl", out, NULL, NULL, 0), AVM_ERROR_IO);

  remove(in);
  remove(out);
  remove(bad);
}

static void test_independent_handles(void) {
  avm_solver* s1 = make_solver();
  avm_solver* s2 = make_solver();
  test_frame f;
  make_tpose(&f, 0.0, 0.f);
  CHECK_STATUS(avm_solver_push(s1, NULL), AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_solver_last_error(s1)[0] != '\0');
  CHECK(strcmp(avm_solver_last_error(s2), "") == 0); /* messages are per handle */
  CHECK_STATUS(avm_solver_push(s2, &f.frame), AVM_OK);
  CHECK(avm_solver_last_error(s1)[0] != '\0');
  avm_solver_destroy(s1);
  avm_solver_destroy(s2);
}

int main(void) {
  test_version();
  test_status_strings();
  test_create_destroy();
  test_null_arguments();
  test_invalid_options();
  test_struct_size_evolution();
  test_sized_init();
  test_bad_frames();
  test_rest_pose();
  test_nan_frame();
  test_bones_and_expressions();
  test_blendshapes();
  test_sample_between_pushes();
  test_solve_file();
  test_independent_handles();
  if (g_failures != 0) {
    fprintf(stderr, "%d check(s) failed\n", g_failures);
    return 1;
  }
  printf("all C API checks passed\n");
  return 0;
}
