/* C API over arrays of frames and poses (avm_frame_block, avm_landmark_reader_*,
 * avm_solve_frames, avm_clip_read / _get_poses / _add_poses, avm_retargeter_apply_poses):
 *   - the reader on a hand-written file (known values, parts missing, 468- and 478-point
 *     faces, NaN fill, NULL arrays skipped, a bad line reported and skipped); its person
 *     column on a hand-written version-2 file, a version-1 file (0) and for a caller whose
 *     struct ends before the column;
 *   - avm_solve_frames refuses a block of several person ids, solves a block of one as
 *     without the column;
 *   - avm_solve_frames on a file's frames gives bit-identical poses to avm_solve_file on the
 *     file (read back with avm_clip_read), for each file filter; on the hand-written file and
 *     on argv[1] (a synthetic recording with hands and face, written by `avatarmap synth`);
 *   - clip add_poses / get_poses round trips, all or nothing; apply_poses equals
 *     avm_retargeter_apply per pose (a generated Mixamo-named rig).
 * Runs in its own build folder (writes and removes a few small files). Prints "N passed, N
 * failed". */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "mixamo_fixture.h"
#include "test_util.h"

#ifndef AVM_TEST_MAPPINGS_DIR
#error "AVM_TEST_MAPPINGS_DIR must name the mappings folder"
#endif

#define PT 5 /* floats per point */

/* A block with every array, for `n` frames (malloc'd; free_block frees them). */
static avm_frame_block new_block(int64_t n) {
  avm_frame_block b;
  const size_t k = (size_t)(n > 0 ? n : 1);
  memset(&b, 0, sizeof b);
  b.struct_size = sizeof b;
  b.count = n;
  b.t = (double*)malloc(k * sizeof(double));
  b.pose = (float*)malloc(k * 33 * PT * sizeof(float));
  b.pose_world = (float*)malloc(k * 33 * PT * sizeof(float));
  b.left_hand = (float*)malloc(k * 21 * PT * sizeof(float));
  b.left_hand_world = (float*)malloc(k * 21 * PT * sizeof(float));
  b.right_hand = (float*)malloc(k * 21 * PT * sizeof(float));
  b.right_hand_world = (float*)malloc(k * 21 * PT * sizeof(float));
  b.face = (float*)malloc(k * 478 * PT * sizeof(float));
  return b;
}

static void free_block(avm_frame_block* b) {
  free(b->t);
  free(b->pose);
  free(b->pose_world);
  free(b->left_hand);
  free(b->left_hand_world);
  free(b->right_hand);
  free(b->right_hand_world);
  free(b->face);
}

/* The value written for point i, field c of a part numbered `part` in frame f: exact in
 * binary (a multiple of 1/256), so the text reads back exactly. */
static float value(int f, int part, int i, int c) {
  return (float)((f * 7 + part * 3 + i + c) % 200) / 256.f;
}

static void write_points(FILE* fp, const char* key, int f, int part, int n) {
  int i;
  fprintf(fp, ",\"%s\":[", key);
  for (i = 0; i < n; ++i)
    fprintf(fp, "%s[%.9g,%.9g,%.9g,%.9g,%.9g]", i ? "," : "", value(f, part, i, 0),
            value(f, part, i, 1), value(f, part, i, 2), value(f, part, i, 3), value(f, part, i, 4));
  fprintf(fp, "]");
}

/* Four frames: 0 body only; 1 body, left hand and a 468-point face; 2 body, right hand and a
 * 478-point face; 3 nothing. A bad line after frame 1 when `bad`. */
static int write_hand_file(const char* path, int bad) {
  FILE* fp = fopen(path, "w");
  int f;
  if (fp == NULL) return 0;
  fprintf(fp,
          "{\"format\":\"avatarmap.landmarks\",\"version\":1,\"image_size\":[640,480],"
          "\"fps\":30}\n");
  for (f = 0; f < 4; ++f) {
    fprintf(fp, "{\"t\":%.9g", 0.5 + f / 32.0);
    if (f < 3) {
      write_points(fp, "pose", f, 0, 33);
      write_points(fp, "pose_world", f, 1, 33);
    }
    if (f == 1) {
      write_points(fp, "left_hand", f, 2, 21);
      write_points(fp, "left_hand_world", f, 3, 21);
      write_points(fp, "face", f, 6, 468);
    }
    if (f == 2) {
      write_points(fp, "right_hand", f, 4, 21);
      write_points(fp, "right_hand_world", f, 5, 21);
      write_points(fp, "face", f, 6, 478);
    }
    fprintf(fp, "}\n");
    if (bad && f == 1) fprintf(fp, "{\"t\":1,\"pose\":[oops]}\n");
  }
  return fclose(fp) == 0;
}

/* 1 when points [0, n) of row f of `array` (of `per` points a frame) hold the written values
 * of `part`, and points [n, per) are NaN. */
static int row_of(const float* array, int per, int row, int f, int part, int n) {
  const float* r = array + (size_t)row * per * PT;
  int i, c;
  for (i = 0; i < per; ++i)
    for (c = 0; c < PT; ++c) {
      const float v = r[i * PT + c];
      if (i < n ? v != value(f, part, i, c) : !isnan(v)) return 0;
    }
  return 1;
}

/* row_of for frame f in row f. */
static int row_is(const float* array, int per, int f, int part, int n) {
  return row_of(array, per, f, f, part, n);
}

static void test_reader(void) {
  const char* path = "frames_test_hand.landmarks.jsonl";
  const char* bad = "frames_test_bad.landmarks.jsonl";
  avm_landmark_reader* r = NULL;
  avm_frame_block b = new_block(3), small;
  int64_t got = -1;
  int32_t w = -1, h = -1;
  double fps = -1.0;

  CHECK(write_hand_file(path, 0));
  CHECK(avm_landmark_reader_open(path, &r) == AVM_OK && r != NULL);
  if (r == NULL) return;
  CHECK(avm_landmark_reader_header(r, &w, &h, &fps) == AVM_OK);
  CHECK(w == 640 && h == 480 && fps == 30.0);
  CHECK(avm_landmark_reader_header(r, NULL, NULL, NULL) == AVM_OK);

  /* Three frames into a block of three, then the last, then the end (0, AVM_OK). */
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 3);
  CHECK(b.t[0] == 0.5 && b.t[1] == 0.5 + 1 / 32.0 && b.t[2] == 0.5 + 2 / 32.0);
  CHECK(row_is(b.pose, 33, 0, 0, 33) && row_is(b.pose_world, 33, 0, 1, 33));
  CHECK(row_is(b.left_hand, 21, 0, 2, 0) && row_is(b.right_hand_world, 21, 0, 5, 0));
  CHECK(row_is(b.face, 478, 0, 6, 0));
  CHECK(row_is(b.left_hand, 21, 1, 2, 21) && row_is(b.left_hand_world, 21, 1, 3, 21));
  CHECK(row_is(b.right_hand, 21, 1, 4, 0));
  CHECK(row_is(b.face, 478, 1, 6, 468)); /* rows 468..477 NaN */
  CHECK(row_is(b.right_hand, 21, 2, 4, 21) && row_is(b.right_hand_world, 21, 2, 5, 21));
  CHECK(row_is(b.left_hand_world, 21, 2, 3, 0));
  CHECK(row_is(b.face, 478, 2, 6, 478));
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 1);
  CHECK(b.t[0] == 0.5 + 3 / 32.0 && isnan(b.pose[0]) && isnan(b.face[0]));
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 0);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 0);
  avm_landmark_reader_destroy(r);

  /* NULL arrays are skipped; the others are filled. */
  memset(&small, 0, sizeof small);
  small.struct_size = sizeof small;
  small.count = 2;
  small.t = b.t;
  small.left_hand = b.left_hand;
  b.left_hand[21 * PT] = 123.f;
  CHECK(avm_landmark_reader_open(path, &r) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &small, &got) == AVM_OK && got == 2);
  CHECK(row_is(b.left_hand, 21, 1, 2, 21) && isnan(b.left_hand[0]));
  avm_landmark_reader_destroy(r);

  /* A bad line: the good frames before it, AVM_ERROR_PARSE naming FILE:LINE, then on. */
  CHECK(write_hand_file(bad, 1));
  CHECK(avm_landmark_reader_open(bad, &r) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_ERROR_PARSE && got == 2);
  CHECK(contains(avm_landmark_reader_last_error(r), "frames_test_bad.landmarks.jsonl:4"));
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 2);
  CHECK(avm_landmark_reader_last_error(r)[0] == '\0');
  CHECK(b.t[0] == 0.5 + 2 / 32.0 && row_of(b.face, 478, 0, 2, 6, 478)); /* frame 2's face */

  /* Bad arguments. */
  small.struct_size = 8;
  CHECK(avm_landmark_reader_read(r, &small, &got) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_landmark_reader_last_error(r), "struct_size"));
  small.struct_size = sizeof small;
  small.count = -1;
  CHECK(avm_landmark_reader_read(r, &small, &got) == AVM_ERROR_INVALID_ARGUMENT);
  small.count = 1;
  small.t = NULL;
  CHECK(avm_landmark_reader_read(r, &small, &got) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_landmark_reader_read(r, NULL, &got) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_landmark_reader_read(r, &b, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_landmark_reader_read(NULL, &b, &got) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_landmark_reader_header(NULL, &w, &h, &fps) == AVM_ERROR_INVALID_ARGUMENT);
  avm_landmark_reader_destroy(r);
  avm_landmark_reader_destroy(NULL);
  CHECK(avm_landmark_reader_last_error(NULL)[0] == '\0');

  r = (avm_landmark_reader*)&got;
  CHECK(avm_landmark_reader_open("does/not/exist.landmarks.jsonl", &r) == AVM_ERROR_IO);
  CHECK(r == NULL && contains(avm_last_create_error(), "does/not/exist"));
  CHECK(avm_landmark_reader_open(NULL, &r) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_landmark_reader_open(path, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  {
    FILE* fp = fopen(bad, "w");
    if (fp != NULL) {
      fputs("{\"format\":\"avatarmap.landmarks\",\"version\":99}\n", fp);
      fclose(fp);
    }
    CHECK(avm_landmark_reader_open(bad, &r) == AVM_ERROR_PARSE && r == NULL);
  }
  remove(bad);
  remove(path);
  free_block(&b);
}

/* A version-2 file (several people), written here line by line: frame 0 has people 0 and 1,
 * frame 1 only person 1, frame 2 people 0 and 2 (ascending by id, one t per frame). Line k's
 * body has the values of `value(k, 0, ...)`. */
static const int k_people_rows = 5;
static const int k_people_ids[] = {0, 1, 1, 0, 2};
static const int k_people_frame[] = {0, 0, 1, 2, 2};

static int write_people_file(const char* path) {
  FILE* fp = fopen(path, "w");
  int k;
  if (fp == NULL) return 0;
  fprintf(fp,
          "{\"format\":\"avatarmap.landmarks\",\"version\":2,\"image_size\":[640,480],"
          "\"fps\":30}\n");
  for (k = 0; k < k_people_rows; ++k) {
    fprintf(fp, "{\"t\":%.9g,\"person\":%d", 0.25 + k_people_frame[k] / 32.0, k_people_ids[k]);
    write_points(fp, "pose", k, 0, 33);
    fprintf(fp, "}\n");
  }
  return fclose(fp) == 0;
}

/* The person column: a version-2 file's ids row by row; a version-1 file's rows are 0; a caller
 * whose struct ends before the column (built before it existed) gets none written. */
static void test_reader_person(void) {
  const char* people = "frames_test_people.landmarks.jsonl";
  const char* one = "frames_test_one.landmarks.jsonl";
  avm_landmark_reader* r = NULL;
  avm_frame_block b = new_block(8);
  int32_t ids[8];
  int64_t got = -1;
  int k;

  CHECK(write_people_file(people));
  for (k = 0; k < 8; ++k) ids[k] = -7;
  b.person = ids;
  CHECK(avm_landmark_reader_open(people, &r) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == k_people_rows);
  for (k = 0; k < k_people_rows; ++k) {
    CHECK(ids[k] == k_people_ids[k]);
    CHECK(b.t[k] == 0.25 + k_people_frame[k] / 32.0);
    CHECK(row_is(b.pose, 33, k, 0, 33));
    CHECK(row_is(b.left_hand, 21, k, 2, 0));
  }
  CHECK(ids[k_people_rows] == -7); /* no more rows than lines */
  avm_landmark_reader_destroy(r);

  /* Blocks of two rows: the ids go on across calls. */
  for (k = 0; k < 8; ++k) ids[k] = -7;
  CHECK(avm_landmark_reader_open(people, &r) == AVM_OK);
  b.count = 2;
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 2);
  CHECK(ids[0] == 0 && ids[1] == 1);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 2);
  CHECK(ids[0] == 1 && ids[1] == 0 && row_of(b.pose, 33, 1, 3, 0, 33));
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 1 && ids[0] == 2);
  b.count = 8;
  avm_landmark_reader_destroy(r);

  /* A version-1 file: every row is person 0. */
  CHECK(write_hand_file(one, 0));
  for (k = 0; k < 8; ++k) ids[k] = -7;
  CHECK(avm_landmark_reader_open(one, &r) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == 4);
  for (k = 0; k < 4; ++k) CHECK(ids[k] == 0);
  avm_landmark_reader_destroy(r);

  /* The struct as a caller built before the column knows it: read as before, nothing written
   * past its end. */
  for (k = 0; k < 8; ++k) ids[k] = -7;
  b.struct_size = (uint32_t)offsetof(avm_frame_block, person);
  CHECK(avm_landmark_reader_open(people, &r) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == k_people_rows);
  CHECK(ids[0] == -7 && ids[1] == -7 && row_is(b.pose, 33, 4, 0, 33));
  b.struct_size = (uint32_t)offsetof(avm_frame_block, person) - 4;
  CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_landmark_reader_last_error(r), "struct_size"));
  avm_landmark_reader_destroy(r);

  b.person = NULL;
  b.struct_size = sizeof b;
  remove(people);
  remove(one);
  free_block(&b);
}

/* avm_solve_frames and the person column: one id is solved as without the column; several are
 * refused with a message that says what to do; a struct without the column solves every row. */
static void test_solve_frames_person(void) {
  avm_frame_block b = new_block(6);
  avm_pose plain[6], with_ids[6];
  int32_t ids[6];
  char err[512];
  int k;
  CHECK(write_people_file("frames_test_solve_people.landmarks.jsonl"));
  {
    avm_landmark_reader* r = NULL;
    int64_t got = 0;
    CHECK(avm_landmark_reader_open("frames_test_solve_people.landmarks.jsonl", &r) == AVM_OK);
    CHECK(avm_landmark_reader_read(r, &b, &got) == AVM_OK && got == k_people_rows);
    avm_landmark_reader_destroy(r);
  }
  remove("frames_test_solve_people.landmarks.jsonl");
  /* Rows 1 and 2 are person 1 (frames 0 and 1): a take of its own. */
  b.t += 1;
  b.pose += 33 * PT;
  b.pose_world += 33 * PT;
  b.left_hand += 21 * PT;
  b.left_hand_world += 21 * PT;
  b.right_hand += 21 * PT;
  b.right_hand_world += 21 * PT;
  b.face += 478 * PT;
  b.count = 2;
  CHECK(avm_solve_frames(&b, NULL, plain, err, sizeof err) == AVM_OK);
  ids[0] = ids[1] = 1;
  b.person = ids;
  memset(with_ids, 0xff, sizeof with_ids);
  CHECK(avm_solve_frames(&b, NULL, with_ids, err, sizeof err) == AVM_OK && err[0] == '\0');
  CHECK(memcmp(plain, with_ids, 2 * sizeof(avm_pose)) == 0);
  /* Two ids: refused, naming the column and the way out. */
  ids[1] = 0;
  CHECK(avm_solve_frames(&b, NULL, with_ids, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "avm_frame_block.person") && contains(err, "avm_solver_options.person"));
  /* Three rows, the odd one last. */
  b.count = 3;
  ids[1] = 1;
  ids[2] = 0;
  CHECK(avm_solve_frames(&b, NULL, with_ids, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  /* A caller without the column: the rows are solved (the column is not its own). */
  b.struct_size = (uint32_t)offsetof(avm_frame_block, person);
  CHECK(avm_solve_frames(&b, NULL, with_ids, err, sizeof err) == AVM_OK);
  b.struct_size = sizeof b;
  b.person = NULL;
  CHECK(avm_solve_frames(&b, NULL, with_ids, err, sizeof err) == AVM_OK);
  for (k = 0; k < 3; ++k) CHECK(with_ids[k].t == b.t[k]);
  b.t -= 1;
  b.pose -= 33 * PT;
  b.pose_world -= 33 * PT;
  b.left_hand -= 21 * PT;
  b.left_hand_world -= 21 * PT;
  b.right_hand -= 21 * PT;
  b.right_hand_world -= 21 * PT;
  b.face -= 478 * PT;
  free_block(&b);
}

/* Every frame of `path` in a new block (*out_count frames); the header's size and rate. */
static avm_frame_block read_all(const char* path, int32_t* w, int32_t* h) {
  avm_landmark_reader* r = NULL;
  avm_frame_block all = new_block(4096);
  int64_t got = 0;
  CHECK(avm_landmark_reader_open(path, &r) == AVM_OK);
  CHECK(avm_landmark_reader_header(r, w, h, NULL) == AVM_OK);
  CHECK(avm_landmark_reader_read(r, &all, &got) == AVM_OK && got > 0 && got < 4096);
  all.count = got;
  avm_landmark_reader_destroy(r);
  return all;
}

/* The *.pose.jsonl reader's rule (src/io/pose_file.cpp): a quaternion whose squared length is
 * more than 4 float epsilons from 1 is normalised in double precision; others are kept bit for
 * bit. The solver's gate can leave a rotation that far from unit length (a blend), so a pose
 * read back from a file is compared with the in-memory pose after this rule. */
static void as_read_back(const avm_pose* in, avm_pose* out) {
  int b, c;
  *out = *in;
  for (b = 0; b < AVM_BONE_COUNT; ++b) {
    const float* v = in->rotations[b];
    const double n2 =
        (double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2] + (double)v[3] * v[3];
    if (fabs(n2 - 1.0) > 4.0 * 1.1920928955078125e-7) {
      const double inv = 1.0 / sqrt(n2);
      for (c = 0; c < 4; ++c) out->rotations[b][c] = (float)(v[c] * inv);
    }
  }
}

/* 1 when the poses match bit for bit in time, hips, rotations and expressions (the pose file
 * has no confidence); `a`'s rotations as the pose reader gives them back. */
static int same_poses(const avm_pose* mem, const avm_pose* file, int64_t n) {
  int64_t i;
  avm_pose a;
  for (i = 0; i < n; ++i) {
    const avm_pose* b = &file[i];
    int hips, rotations, expressions;
    as_read_back(&mem[i], &a);
    hips = memcmp(a.hips_position, b->hips_position, sizeof a.hips_position) != 0;
    rotations = memcmp(a.rotations, b->rotations, sizeof a.rotations) != 0;
    expressions = memcmp(a.expressions, b->expressions, sizeof a.expressions) != 0;
    if (a.t != b->t || hips || rotations || expressions) {
      fprintf(stderr, "poses differ at frame %ld (t %d, hips %d, rotations %d, expressions %d)\n",
              (long)i, a.t != b->t, hips, rotations, expressions);
      return 0;
    }
  }
  return 1;
}

/* avm_solve_frames on the file's frames == avm_solve_file on the file, for each filter. */
static void test_solve_frames_matches_file(const char* path) {
  const char* out = "frames_test_solved.pose.jsonl";
  int32_t w = 0, h = 0;
  avm_frame_block all = read_all(path, &w, &h);
  avm_pose* mem = (avm_pose*)malloc((size_t)all.count * sizeof(avm_pose));
  avm_pose* file = (avm_pose*)malloc((size_t)all.count * sizeof(avm_pose));
  avm_solver_options o;
  avm_clip* clip = NULL;
  char err[512];
  int filter, moved = 0;
  int64_t i;

  for (filter = AVM_FILE_FILTER_OFFLINE; filter <= AVM_FILE_FILTER_NONE; ++filter) {
    avm_solver_options_init(&o);
    o.file_filter = filter;
    CHECK(avm_solve_file(path, out, &o, err, sizeof err) == AVM_OK);
    /* No header in memory: the file's image size given as options. */
    o.image_width = (float)w;
    o.image_height = (float)h;
    memset(mem, 0xff, (size_t)all.count * sizeof(avm_pose));
    CHECK(avm_solve_frames(&all, &o, mem, err, sizeof err) == AVM_OK && err[0] == '\0');
    if (err[0] != '\0') fprintf(stderr, "avm_solve_frames: %s\n", err);
    CHECK(avm_clip_read(out, &clip, err, sizeof err) == AVM_OK && clip != NULL);
    if (clip == NULL) break;
    CHECK(avm_clip_frame_count(clip) == (int)all.count);
    CHECK(avm_clip_get_poses(clip, 0, all.count, file) == AVM_OK);
    if (!same_poses(mem, file, all.count)) {
      CHECK(!"avm_solve_frames == avm_solve_file");
      fprintf(stderr, "(%s, file_filter %d)\n", path, filter);
    }
    avm_clip_destroy(clip);
    clip = NULL;
    /* avm_solve_file_to_clip keeps the same job's poses: bit for bit the in-memory ones,
     * confidence included (a pose file has none). */
    {
      avm_solver_options of;
      avm_solver_options_init(&of);
      of.file_filter = filter;
      CHECK(avm_solve_file_to_clip(path, &of, &clip, err, sizeof err) == AVM_OK && clip != NULL);
      if (clip != NULL) {
        CHECK(avm_clip_frame_count(clip) == (int)all.count);
        CHECK(avm_clip_get_poses(clip, 0, all.count, file) == AVM_OK);
        CHECK(memcmp(mem, file, (size_t)all.count * sizeof(avm_pose)) == 0);
        avm_clip_destroy(clip);
        clip = NULL;
      }
    }
  }
  /* Not a trivial match: the poses move. */
  for (i = 1; i < all.count; ++i)
    moved |= memcmp(mem[i].rotations, mem[0].rotations, sizeof mem[0].rotations) != 0;
  CHECK(moved);
  for (i = 0; i < all.count; ++i) CHECK(mem[i].t == all.t[i]);

  /* Without the image size the poses differ (the size is used). */
  if (w > 0 && w != h) {
    avm_solver_options_init(&o);
    CHECK(avm_solve_frames(&all, &o, mem, err, sizeof err) == AVM_OK);
    CHECK(avm_clip_read(out, &clip, err, sizeof err) == AVM_OK);
    avm_solver_options_init(&o);
    CHECK(avm_solve_file(path, out, &o, err, sizeof err) == AVM_OK);
    avm_clip_destroy(clip);
    CHECK(avm_clip_read(out, &clip, err, sizeof err) == AVM_OK);
    CHECK(avm_clip_get_poses(clip, 0, all.count, file) == AVM_OK);
    CHECK(memcmp(mem[0].rotations, file[0].rotations, sizeof mem[0].rotations) != 0 ||
          memcmp(mem[0].hips_position, file[0].hips_position, sizeof mem[0].hips_position) != 0);
    avm_clip_destroy(clip);
  }
  remove(out);
  free(mem);
  free(file);
  free_block(&all);
}

static void test_solve_file_to_clip_errors(void) {
  avm_clip* clip = (avm_clip*)&clip; /* not NULL: the call must set it */
  avm_solver_options o;
  char err[512];
  CHECK(avm_solve_file_to_clip("no_such_dir/none.landmarks.jsonl", NULL, &clip, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(clip == NULL && strstr(err, "none.landmarks.jsonl") != NULL);
  CHECK(avm_solve_file_to_clip(NULL, NULL, &clip, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_solve_file_to_clip("x.landmarks.jsonl", NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  avm_solver_options_init(&o);
  o.file_smoothing = -1.f;
  CHECK(avm_solve_file_to_clip("x.landmarks.jsonl", &o, &clip, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(clip == NULL && strstr(err, "file_smoothing") != NULL);
}

static void test_solve_frames_errors(void) {
  avm_frame_block b = new_block(2), empty;
  avm_pose poses[2];
  avm_solver_options o;
  char err[256];
  int i;
  for (i = 0; i < 2 * 33 * PT; ++i) b.pose[i] = b.pose_world[i] = NAN;
  free(b.left_hand);
  free(b.left_hand_world);
  free(b.right_hand);
  free(b.right_hand_world);
  free(b.face);
  b.left_hand = b.left_hand_world = b.right_hand = b.right_hand_world = b.face = NULL;
  b.t[0] = 0.0;
  b.t[1] = 0.1;
  /* Nothing seen: rest poses at the frames' times. */
  CHECK(avm_solve_frames(&b, NULL, poses, err, sizeof err) == AVM_OK);
  CHECK(poses[1].t == 0.1 && poses[1].rotations[AVM_BONE_LEFT_UPPER_ARM][3] == 1.f);

  b.t[1] = NAN;
  CHECK(avm_solve_frames(&b, NULL, poses, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "t[1]"));
  b.t[1] = 0.1;
  CHECK(avm_solve_frames(NULL, NULL, poses, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_solve_frames(&b, NULL, NULL, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "out_poses"));
  b.struct_size = 4;
  CHECK(avm_solve_frames(&b, NULL, poses, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "struct_size"));
  b.struct_size = sizeof b;
  b.count = -3;
  CHECK(avm_solve_frames(&b, NULL, poses, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "count"));
  b.count = 2;
  avm_solver_options_init(&o);
  o.file_smoothing = -1.f;
  CHECK(avm_solve_frames(&b, &o, poses, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "file_smoothing"));
  /* No frames: nothing to do. */
  memset(&empty, 0, sizeof empty);
  empty.struct_size = sizeof empty;
  CHECK(avm_solve_frames(&empty, NULL, NULL, NULL, 0) == AVM_OK);
  free_block(&b);
}

/* Frame k of a small motion (as in c_clip_test.c). */
static void motion_pose(int k, avm_pose* p) {
  const float angle = 0.2f * (float)k;
  rest_pose(1.0 + (double)k / 30.0, p);
  p->rotations[AVM_BONE_LEFT_LOWER_ARM][1] = -sinf(angle / 2.f);
  p->rotations[AVM_BONE_LEFT_LOWER_ARM][3] = cosf(angle / 2.f);
  p->rotations[AVM_BONE_HIPS][0] = sinf(angle / 4.f);
  p->rotations[AVM_BONE_HIPS][3] = cosf(angle / 4.f);
  p->hips_position[0] = 0.01f * (float)k;
  p->expressions[AVM_EXPRESSION_AA] = 0.05f * (float)k;
  {
    int b;
    for (b = 0; b < AVM_BONE_COUNT; ++b) p->confidence[b] = 1.f;
  }
}

static void test_clip_poses(void) {
  enum { N = 12 };
  avm_pose in[N], one[N], many[N], back[N];
  avm_clip *a = NULL, *b = NULL, *r = NULL;
  char err[256];
  int k;
  for (k = 0; k < N; ++k) motion_pose(k, &in[k]);
  in[3].rotations[AVM_BONE_SPINE][0] = NAN; /* sanitised alike by both paths */
  in[5].expressions[2] = 2.f;

  CHECK(avm_clip_create(&a) == AVM_OK && avm_clip_create(&b) == AVM_OK);
  for (k = 0; k < N; ++k) CHECK(avm_clip_add(a, &in[k]) == AVM_OK);
  CHECK(avm_clip_add_poses(b, in, 5) == AVM_OK);
  CHECK(avm_clip_add_poses(b, in + 5, N - 5) == AVM_OK);
  CHECK(avm_clip_frame_count(b) == N);
  CHECK(avm_clip_get_poses(a, 0, N, one) == AVM_OK);
  CHECK(avm_clip_get_poses(b, 0, N, many) == AVM_OK);
  CHECK(memcmp(one, many, sizeof one) == 0);
  /* What went in comes out (finite values unchanged: unit quaternions, weights in range). */
  CHECK(memcmp(&many[7], &in[7], sizeof in[7]) == 0);
  CHECK(many[3].confidence[AVM_BONE_SPINE] == 0.f && many[5].expressions[2] == 1.f);
  CHECK(avm_clip_get_poses(b, 4, 3, back) == AVM_OK &&
        memcmp(back, many + 4, 3 * sizeof *back) == 0);
  CHECK(avm_clip_get_poses(b, N, 0, NULL) == AVM_OK);

  /* Out of range, negative, NULL. */
  CHECK(avm_clip_get_poses(b, N - 2, 3, back) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(b), "12 frames"));
  CHECK(avm_clip_get_poses(b, -1, 1, back) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_get_poses(b, 0, -1, back) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_get_poses(b, 0, 1, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_get_poses(NULL, 0, 1, back) == AVM_ERROR_INVALID_ARGUMENT);

  /* All or nothing: a time out of order at index 2 adds none. */
  for (k = 0; k < 4; ++k) rest_pose(10.0 + k, &back[k]);
  back[2].t = 10.5;
  CHECK(avm_clip_add_poses(b, back, 4) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(b), "poses[2]") && avm_clip_frame_count(b) == N);
  back[2].t = NAN;
  CHECK(avm_clip_add_poses(b, back, 4) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(b), "finite") && avm_clip_frame_count(b) == N);
  back[2].t = 12.0;
  back[0].t = in[N - 1].t; /* not after the clip's last frame */
  CHECK(avm_clip_add_poses(b, back, 4) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_clip_last_error(b), "poses[0]") && avm_clip_frame_count(b) == N);
  CHECK(avm_clip_add_poses(b, back, -1) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_add_poses(b, NULL, 1) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_add_poses(b, NULL, 0) == AVM_OK && avm_clip_frame_count(b) == N);
  CHECK(avm_clip_add_poses(NULL, back, 1) == AVM_ERROR_INVALID_ARGUMENT);

  /* Written as .pose.jsonl and read back: the same poses (no confidence in the file). */
  CHECK(avm_clip_write(b, "frames_test_clip.pose.jsonl", 0.0, NULL, NULL, err, sizeof err) ==
        AVM_OK);
  CHECK(avm_clip_read("frames_test_clip.pose.jsonl", &r, err, sizeof err) == AVM_OK);
  CHECK(avm_clip_frame_count(r) == N);
  CHECK(avm_clip_get_poses(r, 0, N, back) == AVM_OK && same_poses(back, many, N));
  avm_clip_destroy(r);

  /* Reading: missing file, bad line, times out of order (sorted). */
  r = a;
  CHECK(avm_clip_read("does/not/exist.pose.jsonl", &r, err, sizeof err) == AVM_ERROR_IO);
  CHECK(r == NULL && contains(err, "does/not/exist"));
  CHECK(avm_clip_read(NULL, &r, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_clip_read("x.pose.jsonl", NULL, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  {
    FILE* fp = fopen("frames_test_bad.pose.jsonl", "w");
    if (fp != NULL) {
      fputs("{\"format\":\"avatarmap.pose\",\"version\":1}\n{\"t\":0,\"bones\":7}\n", fp);
      fclose(fp);
    }
    CHECK(avm_clip_read("frames_test_bad.pose.jsonl", &r, err, sizeof err) == AVM_ERROR_PARSE);
    CHECK(r == NULL && contains(err, "frames_test_bad.pose.jsonl:2"));
    /* Times out of order: sorted by the library's one rule (the reader of avm_convert_file). */
    fp = fopen("frames_test_bad.pose.jsonl", "w");
    if (fp != NULL) {
      fputs("{\"t\":1}\n{\"t\":0.5}\n", fp);
      fclose(fp);
    }
    CHECK(avm_clip_read("frames_test_bad.pose.jsonl", &r, err, sizeof err) == AVM_OK && r != NULL);
    if (r != NULL) {
      CHECK(avm_clip_frame_count(r) == 2);
      CHECK(avm_clip_get_poses(r, 0, 2, back) == AVM_OK && back[0].t == 0.5 && back[1].t == 1.0);
      avm_clip_destroy(r);
      r = NULL;
    }
  }
  remove("frames_test_bad.pose.jsonl");
  remove("frames_test_clip.pose.jsonl");
  avm_clip_destroy(a);
  avm_clip_destroy(b);
}

static void test_apply_poses(void) {
  enum { N = 9 };
  const char* rig = "frames_test_mixamo.gltf";
  avm_pose in[N];
  avm_retargeter *one = NULL, *many = NULL;
  float *rot1, *rot2, hips1[N * 3], hips2[N * 3];
  int j, k, n;
  CHECK(write_mixamo_fixture(rig));
  CHECK(avm_retargeter_create(rig, AVM_TEST_MAPPINGS_DIR "/mixamo.json", &one) == AVM_OK);
  CHECK(avm_retargeter_create(rig, AVM_TEST_MAPPINGS_DIR "/mixamo.json", &many) == AVM_OK);
  if (one == NULL || many == NULL) return;
  n = avm_retargeter_joint_count(one);
  rot1 = (float*)malloc((size_t)(N * n * 4) * sizeof(float));
  rot2 = (float*)malloc((size_t)(N * n * 4) * sizeof(float));
  for (k = 0; k < N; ++k) motion_pose(k, &in[k]);
  in[4].rotations[AVM_BONE_LEFT_UPPER_ARM][2] = NAN; /* identity in both paths */
  for (k = 0; k < N; ++k)
    CHECK(avm_retargeter_apply(one, &in[k], rot1 + k * n * 4, hips1 + 3 * k) == AVM_OK);
  memset(rot2, 0xff, (size_t)(N * n * 4) * sizeof(float));
  CHECK(avm_retargeter_apply_poses(many, in, N, rot2, hips2) == AVM_OK);
  CHECK(memcmp(rot1, rot2, (size_t)(N * n * 4) * sizeof(float)) == 0);
  CHECK(memcmp(hips1, hips2, sizeof hips1) == 0);
  /* The rotations change with the pose (a real answer, not a constant). */
  j = avm_retargeter_bone_joint(one, AVM_BONE_LEFT_LOWER_ARM);
  CHECK(j >= 0 && memcmp(rot2 + j * 4, rot2 + (N - 1) * n * 4 + j * 4, 4 * sizeof(float)) != 0);
  CHECK(hips2[0] != hips2[3 * (N - 1)]);
  /* hips NULL; count 0; errors. */
  CHECK(avm_retargeter_apply_poses(many, in, N, rot2, NULL) == AVM_OK);
  CHECK(memcmp(rot1, rot2, (size_t)(N * n * 4) * sizeof(float)) == 0);
  CHECK(avm_retargeter_apply_poses(many, NULL, 0, NULL, NULL) == AVM_OK);
  CHECK(avm_retargeter_apply_poses(many, in, -1, rot2, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(avm_retargeter_last_error(many), "count"));
  CHECK(avm_retargeter_apply_poses(many, in, 1, NULL, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_retargeter_apply_poses(many, NULL, 1, rot2, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_retargeter_apply_poses(NULL, in, 1, rot2, NULL) == AVM_ERROR_INVALID_ARGUMENT);
  free(rot1);
  free(rot2);
  avm_retargeter_destroy(one);
  avm_retargeter_destroy(many);
  remove(rig);
}

/* An input without a line end (/dev/zero): each read ends (the line cap is enforced while
 * reading, not when the line ends); a caller that goes on gets the input given up, then the
 * end. Was: the first read never returned. */
static void test_reader_endless_line(void) {
  avm_landmark_reader* r = NULL;
  avm_frame_block block;
  double t[4];
  int64_t got = -1;
  if (avm_landmark_reader_open("/dev/zero", &r) != AVM_OK) {
    printf("no /dev/zero here: the endless-line check is skipped\n");
    return;
  }
  memset(&block, 0, sizeof block);
  block.struct_size = sizeof block;
  block.count = 4;
  block.t = t;
  CHECK(avm_landmark_reader_read(r, &block, &got) == AVM_ERROR_PARSE);
  CHECK(strstr(avm_landmark_reader_last_error(r), "line longer than") != NULL);
  CHECK(avm_landmark_reader_read(r, &block, &got) == AVM_ERROR_PARSE);
  CHECK(strstr(avm_landmark_reader_last_error(r), "the rest of the input is not read") != NULL);
  CHECK(avm_landmark_reader_read(r, &block, &got) == AVM_OK && got == 0);
  avm_landmark_reader_destroy(r);
}

int main(int argc, char** argv) {
  test_reader();
  test_reader_person();
  test_reader_endless_line();
  CHECK(write_hand_file("frames_test_solve.landmarks.jsonl", 0));
  test_solve_frames_matches_file("frames_test_solve.landmarks.jsonl");
  remove("frames_test_solve.landmarks.jsonl");
  if (argc > 1) {
    test_solve_frames_matches_file(argv[1]);
  } else {
    printf("no synthetic recording given (argv[1]): the hand-written file only\n");
  }
  test_solve_frames_errors();
  test_solve_frames_person();
  test_solve_file_to_clip_errors();
  test_clip_poses();
  test_apply_poses();
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
