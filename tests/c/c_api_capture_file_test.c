/* avm_capture_file on real input: tfjs-models' pose_squats.mp4 (65 frames) gives byte for
 * byte the file the CLI's `avatarmap capture VIDEO -o OUT --hands --face` writes (argv[1] is
 * the CLI), with a summary that agrees with the file and progress that ends at the frame
 * count; pose.jpg gives one frame with a body; three_people.jpg with max_people 3 gives the
 * CLI's `--people 3` file byte for byte and the people's counts (ids 0, 1, 2); devices, missing
 * input, bad arguments (max_people 0 and 9 among them) and an unwritable output fail with a
 * message. Skipped (77) without $AVATARMAP_TEST_DATA,
 * $AVATARMAP_MODELS or the data. Prints "N passed, N failed". */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "test_util.h"

#define SKIP 77

typedef struct progress_log {
  int calls;
  int64_t last_done, last_total;
  int monotonic;
} progress_log;

static void on_progress(void* user, int64_t done, int64_t total) {
  progress_log* p = (progress_log*)user;
  if (done < p->last_done) p->monotonic = 0;
  ++p->calls;
  p->last_done = done;
  p->last_total = total;
}

/* The whole file into a malloc'd NUL-terminated buffer (NULL when it cannot be read). */
static char* slurp(const char* path, long* size) {
  FILE* f = fopen(path, "rb");
  char* buf;
  long n;
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  n = ftell(f);
  fseek(f, 0, SEEK_SET);
  buf = (char*)malloc((size_t)n + 1);
  if (buf != NULL && fread(buf, 1, (size_t)n, f) != (size_t)n) {
    free(buf);
    buf = NULL;
  }
  fclose(f);
  if (buf != NULL) buf[n] = '\0';
  *size = n;
  return buf;
}

/* Frame lines of a landmark file that contain `key` (e.g. "\"left_hand\":"). */
static long lines_with(const char* text, const char* key) {
  long n = 0;
  const char* line = text;
  while (*line != '\0') {
    const char* end = strchr(line, '\n');
    const size_t len = end != NULL ? (size_t)(end - line) : strlen(line);
    const char* hit = strstr(line, key);
    if (hit != NULL && (size_t)(hit - line) < len) ++n;
    if (end == NULL) break;
    line = end + 1;
  }
  return n;
}

int main(int argc, char** argv) {
  const char* data = getenv("AVATARMAP_TEST_DATA");
  const char* models = getenv("AVATARMAP_MODELS");
  char video[1024], image[1024], people[1024], models_dir[1024], command[4096], err[1024];
  const char* cli_out = "capture_file_cli.landmarks.jsonl";
  const char* c_out = "capture_file_c.landmarks.jsonl";
  avm_estimator_options o;
  avm_capture_summary s;
  progress_log log = {0, 0, 0, 1};
  char *cli_text, *c_text;
  long cli_size = 0, c_size = 0;

  if (data == NULL || *data == '\0' || models == NULL || *models == '\0') {
    printf("skipped: set AVATARMAP_TEST_DATA and AVATARMAP_MODELS\n");
    return SKIP;
  }
  snprintf(video, sizeof video, "%s/motion/tfjs-models/pose_squats.mp4", data);
  snprintf(image, sizeof image, "%s/motion/tfjs-models/pose.jpg", data);
  snprintf(people, sizeof people, "%s/motion/tfjs-models/three_people.jpg", data);
  snprintf(models_dir, sizeof models_dir, "%s/onnx", models);
  if (!file_exists(video) || !file_exists(image)) {
    printf("skipped: %s or pose.jpg missing\n", video);
    return SKIP;
  }
  if (argc < 2) {
    fprintf(stderr, "usage: c_api_capture_file_test AVATARMAP_CLI\n");
    return 2;
  }

  /* A build without ONNX Runtime (the sanitizer build) has nothing to capture with. */
  {
    char probe[512];
    avm_estimator_options_init(&o);
    o.models_dir = models_dir;
    if (avm_capture_file(image, c_out, &o, NULL, NULL, NULL, probe, sizeof probe) ==
        AVM_ERROR_UNSUPPORTED) {
      printf("skipped: %s\n", probe);
      return SKIP;
    }
  }

  /* The CLI's capture of the video, then the C API's. */
  remove(cli_out);
  snprintf(command, sizeof command, "\"%s\" capture \"%s\" -o %s --hands --face --quiet", argv[1],
           video, cli_out);
  CHECK(system(command) == 0);
  avm_estimator_options_init(&o);
  o.models_dir = models_dir;
  memset(&s, 0xff, sizeof s);
  s.struct_size = sizeof s;
  CHECK(avm_capture_file(video, c_out, &o, &s, on_progress, &log, err, sizeof err) == AVM_OK);
  if (err[0] != '\0') fprintf(stderr, "avm_capture_file: %s\n", err);
  cli_text = slurp(cli_out, &cli_size);
  c_text = slurp(c_out, &c_size);
  CHECK(cli_text != NULL && c_text != NULL);
  if (cli_text != NULL && c_text != NULL) {
    CHECK(cli_size == c_size && memcmp(cli_text, c_text, (size_t)c_size) == 0);
    /* The summary agrees with the file (one header line, then a line per frame). */
    CHECK(s.frames == 65 && lines_with(c_text, "\"t\":") == s.frames);
    CHECK(s.body_frames == lines_with(c_text, "\"pose\":") && s.body_frames > 50);
    CHECK(s.left_hand_frames == lines_with(c_text, "\"left_hand\":"));
    CHECK(s.right_hand_frames == lines_with(c_text, "\"right_hand\":"));
    CHECK(s.face_frames == lines_with(c_text, "\"face\":") && s.face_frames > 0);
    CHECK(s.left_hand_frames + s.right_hand_frames > 0);
  }
  CHECK(s.frames_not_decoded == 0);
  CHECK(s.image_width == 720 && s.image_height == 1280 && s.fps > 0.0);
  CHECK(s.seconds > 0.0 && s.seconds < 600.0);
  CHECK(log.calls >= 1 && log.monotonic && log.last_done == 65 && log.last_total == 65);
  free(cli_text);
  free(c_text);

  /* A still image: one frame with a body; NULL options (models from $AVATARMAP_MODELS), no
   * summary, no progress. */
  CHECK(avm_capture_file(image, c_out, NULL, NULL, NULL, NULL, err, sizeof err) == AVM_OK);
  c_text = slurp(c_out, &c_size);
  CHECK(c_text != NULL && lines_with(c_text, "\"t\":") == 1 &&
        lines_with(c_text, "\"pose\":") == 1);
  free(c_text);

  /* Several people: three_people.jpg with max_people 3 is the CLI's `--people 3` file, with
   * ids 0, 1, 2; a summary struct of before the people's fields gets none of them. */
  if (file_exists(people)) {
    remove(cli_out);
    snprintf(command, sizeof command,
             "\"%s\" capture \"%s\" -o %s --people 3 --hands --face --models \"%s\" --quiet",
             argv[1], people, cli_out, models_dir);
    CHECK(system(command) == 0);
    avm_estimator_options_init(&o);
    o.models_dir = models_dir;
    o.max_people = 3;
    memset(&s, 0xff, sizeof s);
    s.struct_size = sizeof s;
    CHECK(avm_capture_file(people, c_out, &o, &s, NULL, NULL, err, sizeof err) == AVM_OK);
    cli_text = slurp(cli_out, &cli_size);
    c_text = slurp(c_out, &c_size);
    CHECK(cli_text != NULL && c_text != NULL);
    if (cli_text != NULL && c_text != NULL) {
      CHECK(cli_size == c_size && memcmp(cli_text, c_text, (size_t)c_size) == 0);
      CHECK(lines_with(c_text, "\"version\":2") == 1);
      CHECK(lines_with(c_text, "\"person\":0,") == 1 && lines_with(c_text, "\"person\":1,") == 1 &&
            lines_with(c_text, "\"person\":2,") == 1);
      CHECK(s.frames == 1 && s.people_ids == 3 && s.person_lines == 3 &&
            s.frames_with_people == 1 && s.body_frames == 3);
    }
    free(cli_text);
    free(c_text);
    memset(&s, 0x5a, sizeof s);
    s.struct_size = (uint32_t)offsetof(avm_capture_summary, people_ids);
    CHECK(avm_capture_file(people, c_out, &o, &s, NULL, NULL, err, sizeof err) == AVM_OK);
    CHECK(s.frames == 1 && s.body_frames == 3);
    {
      int64_t untouched;
      memset(&untouched, 0x5a, sizeof untouched);
      CHECK(s.people_ids == untouched && s.frames_with_people == untouched);
    }
    /* One person (the default): none of the people's counts. */
    avm_estimator_options_init(&o);
    o.models_dir = models_dir;
    CHECK(o.max_people == 1);
    s.struct_size = sizeof s;
    CHECK(avm_capture_file(people, c_out, &o, &s, NULL, NULL, err, sizeof err) == AVM_OK);
    CHECK(s.people_ids == 0 && s.person_lines == 0 && s.body_frames == 1);
    /* Out of range: refused, naming the field. */
    o.max_people = 0;
    CHECK(avm_capture_file(people, c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(err, "avm_estimator_options.max_people"));
    o.max_people = AVM_MAX_PEOPLE + 1;
    CHECK(avm_capture_file(people, c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
          AVM_ERROR_INVALID_ARGUMENT);
    CHECK(contains(err, "avm_estimator_options.max_people"));
    /* A caller built before max_people (its struct ends at static_images) gets one person. */
    avm_estimator_options_init(&o);
    o.models_dir = models_dir;
    o.struct_size = (uint32_t)offsetof(avm_estimator_options, max_people);
    o.max_people = 7; /* past the caller's struct: not read */
    CHECK(avm_capture_file(people, c_out, &o, NULL, NULL, NULL, err, sizeof err) == AVM_OK);
    c_text = slurp(c_out, &c_size);
    CHECK(c_text != NULL && lines_with(c_text, "\"person\"") == 0 &&
          lines_with(c_text, "\"pose\":") == 1);
    free(c_text);
    avm_estimator_options_init(&o);
    o.models_dir = models_dir;
    CHECK(avm_capture_file(image, c_out, &o, NULL, NULL, NULL, err, sizeof err) == AVM_OK);
  } else {
    printf("three_people.jpg is missing: the several-people checks are skipped\n");
  }

  /* Failures: nothing written over the output. */
  CHECK(avm_capture_file("lavfi:testsrc=size=64x64:rate=5", c_out, &o, NULL, NULL, NULL, err,
                         sizeof err) == AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "device or stream"));
  CHECK(avm_capture_file("udp://127.0.0.1:5000", c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_capture_file("does/not/exist.mp4", c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_IO);
  CHECK(contains(err, "does/not/exist.mp4"));
  CHECK(avm_capture_file(video, "no/such/folder/x.landmarks.jsonl", &o, NULL, NULL, NULL, err,
                         sizeof err) == AVM_ERROR_IO);
  CHECK(contains(err, "no/such/folder"));
  CHECK(avm_capture_file(NULL, c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(avm_capture_file(video, NULL, &o, NULL, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  s.struct_size = 4;
  CHECK(avm_capture_file(video, c_out, &o, &s, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "struct_size"));
  o.threads = 0;
  CHECK(avm_capture_file(video, c_out, &o, NULL, NULL, NULL, err, sizeof err) ==
        AVM_ERROR_INVALID_ARGUMENT);
  CHECK(contains(err, "threads"));
  avm_estimator_options_init(&o);
  o.models_dir = "no/models/here";
  CHECK(avm_capture_file(video, c_out, &o, NULL, NULL, NULL, err, sizeof err) == AVM_ERROR_IO);
  CHECK(contains(err, "no/models/here"));
  /* The last good output (pose.jpg's one frame) is untouched by the failures. */
  c_text = slurp(c_out, &c_size);
  CHECK(c_text != NULL && lines_with(c_text, "\"t\":") == 1);
  free(c_text);

  remove(cli_out);
  remove(c_out);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
