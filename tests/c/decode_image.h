/* Test photographs as packed RGB for the C API's capture tests, decoded by the ffmpeg
 * command, and a short sleep. The including file defines _POSIX_C_SOURCE 200809L before any
 * include (popen, nanosleep). */
#ifndef AVATARMAP_TESTS_C_DECODE_IMAGE_H
#define AVATARMAP_TESTS_C_DECODE_IMAGE_H

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static inline void sleep_ms(int ms) {
  struct timespec ts;
  ts.tv_sec = ms / 1000;
  ts.tv_nsec = (long)(ms % 1000) * 1000000L;
  nanosleep(&ts, NULL);
}

/* Decodes `path` to packed RGB of width x height with the ffmpeg command; NULL when that
 * fails. The caller frees the pixels. */
static inline unsigned char* decode_rgb(const char* path, int width, int height) {
  char cmd[2048];
  unsigned char* px;
  size_t need = (size_t)width * (size_t)height * 3u, got;
  FILE* p;
  snprintf(cmd, sizeof cmd,
           "ffmpeg -v error -i '%s' -f rawvideo -pix_fmt rgb24 -s %dx%d - 2>/dev/null", path, width,
           height);
  p = popen(cmd, "r");
  if (p == NULL) return NULL;
  px = (unsigned char*)malloc(need);
  got = px != NULL ? fread(px, 1, need, p) : 0;
  pclose(p);
  if (got != need) {
    free(px);
    return NULL;
  }
  return px;
}

#endif
