/* A minimal check macro for the C API tests: counts passes and failures; each test's main
 * prints "N passed, N failed" (a closing line CI reads) and exits non-zero on a failure. */
#ifndef AVATARMAP_TESTS_C_CHECK_H
#define AVATARMAP_TESTS_C_CHECK_H

#include <stdio.h>

static int g_passed = 0, g_failed = 0;
#define CHECK(cond)                                                            \
  do {                                                                         \
    if (cond) {                                                                \
      ++g_passed;                                                              \
    } else {                                                                   \
      ++g_failed;                                                              \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
    }                                                                          \
  } while (0)

#endif
