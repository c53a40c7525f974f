/* Small helpers shared by the C API tests (C99). static inline: a test that does not use one
 * gets no unused-function warning. */
#ifndef AVATARMAP_TESTS_C_TEST_UTIL_H
#define AVATARMAP_TESTS_C_TEST_UTIL_H

#include <stdio.h>
#include <string.h>

#include "avatarmap/avatarmap.h"

/* 1 when `s` is not NULL and contains `part`. */
static inline int contains(const char* s, const char* part) {
  return s != NULL && strstr(s, part) != NULL;
}

/* 1 when `path` can be opened for reading. */
static inline int file_exists(const char* path) {
  FILE* f = fopen(path, "rb");
  if (f == NULL) return 0;
  fclose(f);
  return 1;
}

/* The rest pose at time `t`: identity rotations, hips 0.95 m above the floor, no expressions. */
static inline void rest_pose(double t, avm_pose* p) {
  int b;
  memset(p, 0, sizeof *p);
  p->t = t;
  p->hips_position[1] = 0.95f;
  for (b = 0; b < AVM_BONE_COUNT; ++b) p->rotations[b][3] = 1.f;
}

#endif
