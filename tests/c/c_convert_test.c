/* avm_convert_file against the CLI's `avatarmap convert` (argv[1]: the CLI): the same input
 * and options give the same bytes, for landmarks, poses, a pose file whose frames are out of
 * order (sorted with one warning, for every output) and a .vrma the CLI wrote, with and
 * without the built-in avatar; avm_motion_input_kind's rule; avm_clip_read with the same
 * reader; refusals with their codes. Runs in its own folder (writes a few small files there).
 * Without the CLI the comparisons are skipped (77). Prints "N passed, N failed". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"

static const char* g_cli = NULL;

static int contains(const char* s, const char* part) {
  return s != NULL && strstr(s, part) != NULL;
}

/* The whole file in a malloc'ed buffer (NULL when it cannot be read); *size its length. */
static char* slurp(const char* path, long* size) {
  FILE* f = fopen(path, "rb");
  char* buf = NULL;
  long n = 0;
  if (f == NULL) return NULL;
  if (fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
    buf = (char*)malloc((size_t)n + 1);
    if (buf != NULL && fread(buf, 1, (size_t)n, f) != (size_t)n) {
      free(buf);
      buf = NULL;
    }
  }
  fclose(f);
  *size = n;
  return buf;
}

static int same_bytes(const char* a, const char* b) {
  long na = -1, nb = -2;
  char* x = slurp(a, &na);
  char* y = slurp(b, &nb);
  int same = x != NULL && y != NULL && na == nb && memcmp(x, y, (size_t)na) == 0;
  if (!same) fprintf(stderr, "%s (%ld bytes) and %s (%ld bytes) differ\n", a, na, b, nb);
  free(x);
  free(y);
  return same;
}

static int run_cli(const char* args) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "\"%s\" %s >cli.log 2>&1", g_cli, args);
  return system(cmd);
}

/* Copies `in` to `out` with lines 4 and 5 (1-based) swapped: a pose file whose frames 2 and 3
 * are out of time order (line 1 is the header). */
static int swap_lines_4_5(const char* in, const char* out) {
  long n = 0, i, start[8] = {0};
  int line = 1;
  char* b = slurp(in, &n);
  FILE* f;
  if (b == NULL) return 0;
  for (i = 0; i < n && line < 7; ++i)
    if (b[i] == '\n') start[++line] = i + 1;
  f = fopen(out, "wb");
  if (f == NULL || line < 7) {
    free(b);
    if (f != NULL) fclose(f);
    return 0;
  }
  fwrite(b, 1, (size_t)start[4], f);                         /* lines 1-3 */
  fwrite(b + start[5], 1, (size_t)(start[6] - start[5]), f); /* line 5 */
  fwrite(b + start[4], 1, (size_t)(start[5] - start[4]), f); /* line 4 */
  fwrite(b + start[6], 1, (size_t)(n - start[6]), f);        /* the rest */
  fclose(f);
  free(b);
  return 1;
}

static int g_warnings = 0;
static char g_last_warning[512];
static void on_warning(void* user, const char* message) {
  ++*(int*)user;
  snprintf(g_last_warning, sizeof g_last_warning, "%s", message);
}

/* avm_convert_file(in, "c" + out) and `avatarmap convert in -o "cli" + out cli_args` give the
 * same bytes. */
static void same_as_cli(const char* in, const char* ext, double fps, const char* avatar,
                        const char* cli_args, int warnings_expected) {
  char mine[256], theirs[256], args[1024], err[512];
  avm_convert_options o;
  avm_convert_summary s;
  avm_status st;
  snprintf(mine, sizeof mine, "c_%s%s", in, ext);
  snprintf(theirs, sizeof theirs, "cli_%s%s", in, ext);
  avm_convert_options_init(&o);
  o.fps = fps;
  o.avatar = avatar;
  o.warning = on_warning;
  o.user = &g_warnings;
  g_warnings = 0;
  memset(&s, 0, sizeof s);
  s.struct_size = sizeof s;
  st = avm_convert_file(in, mine, &o, &s, err, sizeof err);
  CHECK(st == AVM_OK);
  if (st != AVM_OK) fprintf(stderr, "avm_convert_file(%s, %s): %s\n", in, mine, err);
  CHECK(g_warnings == warnings_expected);
  CHECK(s.frames_out_of_order == warnings_expected);
  CHECK(s.frames_read > 0 && s.frames_written > 0);
  snprintf(args, sizeof args, "convert %s -o %s %s", in, theirs, cli_args);
  CHECK(run_cli(args) == 0);
  CHECK(same_bytes(mine, theirs));
}

int main(int argc, char** argv) {
  char err[512];
  size_t stem = 0;
  avm_convert_options o;
  avm_convert_summary s;
  avm_clip* clip = NULL;
  g_cli = argc > 1 ? argv[1] : NULL;

  /* The rule for what a motion file is. */
  CHECK(avm_motion_input_kind("a/take.landmarks.jsonl", &stem) == AVM_MOTION_INPUT_LANDMARKS);
  CHECK(stem == strlen("a/take"));
  CHECK(avm_motion_input_kind("X.POSE.JSONL", &stem) == AVM_MOTION_INPUT_POSES && stem == 1);
  CHECK(avm_motion_input_kind("clip.Vrma", NULL) == AVM_MOTION_INPUT_VRMA);
  CHECK(avm_motion_input_kind("-", NULL) == AVM_MOTION_INPUT_LANDMARKS);
  CHECK(avm_motion_input_kind("walk.bvh", &stem) == AVM_MOTION_INPUT_BVH && stem == 4);
  CHECK(avm_motion_input_kind(NULL, &stem) == AVM_MOTION_INPUT_NONE);

  /* Defaults and refusals that need no file. */
  CHECK(avm_convert_options_init(&o) == AVM_OK);
  CHECK(o.struct_size == sizeof o && o.fps == 0.0 && o.avatar == NULL && o.mapping == NULL &&
        o.root_motion == 1 && o.keep_feet_on_ground == 0 && o.solver == NULL && o.warning == NULL);
  CHECK(avm_convert_options_init_sized(&o, 8) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_convert_options_init_sized(NULL, sizeof o) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_convert_file(NULL, "x.vrma", NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_convert_file("missing.pose.jsonl", "x.glb", NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, ".glb output needs options->avatar"));
  CHECK(avm_convert_file("missing.pose.jsonl", "x.fbx", NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_convert_file("missing.pose.jsonl", "x.vrma", NULL, NULL, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "missing.pose.jsonl"));
  o.fps = 1e9;
  CHECK(avm_convert_file("missing.pose.jsonl", "x.vrma", &o, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "fps"));
  avm_convert_options_init(&o);
  o.struct_size = 5000;
  CHECK(avm_convert_file("missing.pose.jsonl", "x.vrma", &o, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  memset(&s, 0, sizeof s);
  s.struct_size = 4;
  CHECK(avm_convert_file("missing.pose.jsonl", "x.vrma", NULL, &s, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);

  if (g_cli == NULL) {
    SKIP_PART("no avatarmap CLI given (argv[1]): the comparisons with `avatarmap convert`");
    return check_exit();
  }
  /* Inputs: synthetic landmarks, their poses, the poses out of order, a .vrma the CLI wrote,
   * the built-in avatar. */
  CHECK(run_cli("synth -o in.landmarks.jsonl --scenario noisy --seconds 2 --seed 9") == 0);
  CHECK(run_cli("solve in.landmarks.jsonl -o in.pose.jsonl") == 0);
  CHECK(swap_lines_4_5("in.pose.jsonl", "ooo.pose.jsonl"));
  CHECK(run_cli("convert in.pose.jsonl -o in.vrma") == 0);
  CHECK(run_cli("avatar -o builtin.vrm") == 0);

  same_as_cli("in.landmarks.jsonl", ".vrma", 30.0, NULL, "", 0);
  same_as_cli("in.landmarks.jsonl", ".pose.jsonl", 0.0, NULL, "", 0);
  same_as_cli("in.pose.jsonl", ".bvh", 24.0, NULL, "--fps 24", 0);
  same_as_cli("ooo.pose.jsonl", ".pose.jsonl", 0.0, NULL, "", 1);
  CHECK(contains(g_last_warning, "1 frame(s) of ooo.pose.jsonl were out of time order"));
  same_as_cli("ooo.pose.jsonl", ".vrma", 30.0, NULL, "", 1);
  same_as_cli("ooo.pose.jsonl", ".glb", 0.0, "builtin.vrm", "--avatar builtin.vrm", 1);
  same_as_cli("in.vrma", ".pose.jsonl", 0.0, NULL, "", 0);
  same_as_cli("in.vrma", ".bvh", 30.0, "builtin.vrm", "--avatar builtin.vrm", 0);
  /* Sorted, the out-of-order file is the in-order one. */
  CHECK(same_bytes("c_ooo.pose.jsonl.pose.jsonl", "in.pose.jsonl"));

  /* Solver options apply to landmarks only. */
  {
    avm_solver_options so;
    avm_solver_options_init(&so);
    avm_convert_options_init(&o);
    o.solver = &so;
    CHECK(avm_convert_file("in.pose.jsonl", "x.vrma", &o, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(err, "landmarks.jsonl input only"));
    so.file_threads = 1;
    o.fps = 30.0;
    CHECK(avm_convert_file("in.landmarks.jsonl", "c_threads1.vrma", &o, NULL, err, sizeof err) ==
          AVM_OK);
    CHECK(same_bytes("c_threads1.vrma", "cli_in.landmarks.jsonl.vrma"));
    so.file_threads = 3;
    CHECK(avm_convert_file("in.landmarks.jsonl", "x.vrma", &o, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(err, "file_threads"));
  }

  /* avm_clip_read reads with the same reader: the frames in time order. */
  CHECK(avm_clip_read("ooo.pose.jsonl", &clip, err, sizeof err) == AVM_OK && clip != NULL);
  if (clip != NULL) {
    avm_clip* ref = NULL;
    CHECK(avm_clip_read("in.pose.jsonl", &ref, err, sizeof err) == AVM_OK && ref != NULL);
    if (ref != NULL) {
      int n = avm_clip_frame_count(clip), i;
      avm_pose* a = (avm_pose*)malloc((size_t)n * sizeof(avm_pose));
      avm_pose* b = (avm_pose*)malloc((size_t)n * sizeof(avm_pose));
      CHECK(n > 0 && n == avm_clip_frame_count(ref));
      if (a != NULL && b != NULL && n > 0) {
        CHECK(avm_clip_get_poses(clip, 0, n, a) == AVM_OK);
        CHECK(avm_clip_get_poses(ref, 0, n, b) == AVM_OK);
        for (i = 1; i < n; ++i) CHECK(a[i].t > a[i - 1].t);
        CHECK(memcmp(a, b, (size_t)n * sizeof(avm_pose)) == 0);
      }
      free(a);
      free(b);
      avm_clip_destroy(ref);
    }
    avm_clip_destroy(clip);
  }
  clip = NULL;
  CHECK(avm_clip_read("in.vrma", &clip, err, sizeof err) == AVM_OK && clip != NULL);
  avm_clip_destroy(clip);
  clip = NULL;
  CHECK(avm_clip_read("in.landmarks.jsonl", &clip, err, sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(clip == NULL && contains(err, "a landmark file"));
  return check_exit();
}
