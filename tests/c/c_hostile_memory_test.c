/* Running out of memory inside the C API: a clip that resamples to millions of frames (within
 * the documented limits) is written in a child process whose address space is capped at
 * 512 MiB, so the library's allocation fails. avm_clip_write must return
 * AVM_ERROR_OUT_OF_MEMORY with a message in our words naming the file, the process must
 * live on (no abort, no signal), and no output or temporary file may be left. Skipped under
 * AddressSanitizer, whose shadow memory cannot live under an address-space cap.
 * Prints "N passed, N failed". */
#define _XOPEN_SOURCE 700
#include <dirent.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "test_util.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AVM_TEST_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define AVM_TEST_ASAN 1
#endif

#ifndef AVM_TEST_ASAN
/* In the child: 2 frames 80,000 s apart written at 50 fps = 4,000,001 frames (under the
 * 4,194,304 limit) of about 1 KB each: far over 512 MiB. Exit code 0 when the call failed as
 * it should, 1..4 naming what was wrong. */
static int child(void) {
  struct rlimit cap;
  avm_clip* clip = NULL;
  avm_pose p;
  char err[1024];
  avm_status st;
  if (avm_clip_create(&clip) != AVM_OK) return 4;
  rest_pose(0.0, &p);
  if (avm_clip_add(clip, &p) != AVM_OK) return 4;
  rest_pose(80000.0, &p);
  if (avm_clip_add(clip, &p) != AVM_OK) return 4;
  cap.rlim_cur = cap.rlim_max = (rlim_t)512 << 20;
  if (setrlimit(RLIMIT_AS, &cap) != 0) return 4;
  st = avm_clip_write(clip, "oom.vrma", 50.0, NULL, NULL, err, sizeof err);
  fprintf(stderr, "  avm_clip_write: %s: %s\n", avm_status_string(st), err);
  avm_clip_destroy(clip);
  if (st != AVM_ERROR_OUT_OF_MEMORY) return 1;
  if (strstr(err, "oom.vrma") == NULL || strstr(err, "memory") == NULL) return 2;
  if (strstr(err, "std::") != NULL || strstr(err, "bad_alloc") != NULL) return 3;
  return 0;
}

/* Any file in the working folder whose name starts with "oom.vrma" or ".oom.vrma". */
static int leftovers(void) {
  DIR* d = opendir(".");
  struct dirent* e;
  int n = 0;
  if (d == NULL) return -1;
  while ((e = readdir(d)) != NULL)
    if (strncmp(e->d_name, "oom.vrma", 8) == 0 || strncmp(e->d_name, ".oom.vrma", 9) == 0) ++n;
  closedir(d);
  return n;
}

#endif /* !AVM_TEST_ASAN */

int main(void) {
#ifdef AVM_TEST_ASAN
  (void)g_passed;
  (void)g_failed;
  printf("skipped: the address-space cap cannot be used under AddressSanitizer\n");
  return 0;
#else
  int status = 0;
  pid_t pid;
  remove("oom.vrma");
  pid = fork();
  CHECK(pid >= 0);
  if (pid == 0) _exit(child());
  CHECK(waitpid(pid, &status, 0) == pid);
  CHECK(WIFEXITED(status)); /* not killed by a signal (an uncaught bad_alloc would abort) */
  if (WIFEXITED(status)) {
    CHECK(WEXITSTATUS(status) == 0);
    if (WEXITSTATUS(status) != 0) fprintf(stderr, "  child exit %d\n", WEXITSTATUS(status));
  } else {
    fprintf(stderr, "  child killed by signal %d\n", WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  }
  CHECK(leftovers() == 0);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
#endif
}
