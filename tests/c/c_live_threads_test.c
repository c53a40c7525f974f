/* Thread misuse of the live handle (avm_live_*), as engines' camera and render callbacks do it:
 * (1) destroy while another thread pushes and a third samples, (2) two threads pushing at
 * once, (3) push, sample and destroy from three threads with no order between them. Each
 * scenario runs for $AVATARMAP_STRESS_SECONDS seconds (default 2; the figures in docs/c-api.md
 * come from 60 s runs under ASan and TSan). Expected: no crash and no sanitizer report; pushes
 * that raced a destroy fail with AVM_ERROR_INVALID_ARGUMENT and say the handle was destroyed;
 * every successful push is counted exactly once. The image is a synthetic gray one (the
 * detector finds no person: the worker still runs the models on every image). Needs
 * $AVATARMAP_MODELS; exits 77 (skipped) without it or on a build without ONNX Runtime. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "avatarmap/avatarmap.h"
#include "check.h"

#define SKIP 77
enum { k_width = 192, k_height = 160 };

static unsigned char g_pixels[k_width * k_height * 3]; /* filled once, before any thread */

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void sleep_ms(int ms) {
  struct timespec ts;
  ts.tv_sec = ms / 1000;
  ts.tv_nsec = (long)(ms % 1000) * 1000000L;
  nanosleep(&ts, NULL);
}

static avm_image gray_image(void) {
  avm_image img;
  img.data = g_pixels;
  img.width = k_width;
  img.height = k_height;
  img.stride_bytes = k_width * 3;
  img.format = AVM_PIXEL_RGB8;
  return img;
}

typedef struct worker_args {
  avm_live* live;
  int index;    /* pusher number (time stamps stay increasing per pusher) */
  double until; /* stop at this time (monotonic seconds) even if never refused */
  long ok;      /* calls that succeeded */
  long refused; /* calls refused as on a destroyed handle */
  long other;   /* any other failure */
  int said_destroyed;
} worker_args;

static void note(worker_args* a, avm_status st) {
  if (st == AVM_OK || st == AVM_ERROR_END_OF_FILE) {
    ++a->ok;
  } else if (st == AVM_ERROR_INVALID_ARGUMENT) {
    char err[256];
    ++a->refused;
    if (strstr(avm_live_last_error(a->live, err, sizeof err), "destroyed") != NULL)
      a->said_destroyed = 1;
  } else {
    ++a->other;
  }
}

/* Pushes until refused (the handle was destroyed) or the time is up. */
static void* pusher(void* arg) {
  worker_args* a = (worker_args*)arg;
  const avm_image img = gray_image();
  long i = 0;
  while (a->refused == 0 && now_s() < a->until) {
    note(a, avm_live_push(a->live, &img, a->index * 1e6 + (double)(i++) / 30.0));
    if ((i & 7) == 0) sleep_ms(1);
  }
  return NULL;
}

/* Samples, asks the newest pose and the stats until refused or the time is up. */
static void* sampler(void* arg) {
  worker_args* a = (worker_args*)arg;
  avm_pose pose;
  avm_live_stats st;
  long i = 0;
  while (a->refused == 0 && now_s() < a->until) {
    note(a, avm_live_sample(a->live, (double)(i++) / 60.0, &pose));
    if (a->refused) break;
    note(a, avm_live_latest(a->live, &pose));
    if (a->refused) break;
    note(a, avm_live_get_stats(a->live, &st));
  }
  return NULL;
}

typedef struct closer_args {
  avm_live* live;
  int delay_ms;
} closer_args;

static void* closer(void* arg) {
  closer_args* c = (closer_args*)arg;
  sleep_ms(c->delay_ms);
  avm_live_destroy(c->live);
  return NULL;
}

static avm_live* create_live(void) {
  avm_estimator_options eo;
  avm_live* live = NULL;
  avm_estimator_options_init(&eo);
  eo.hands = 0;
  eo.face = 0;
  eo.threads = 1;
  if (avm_live_create(&eo, NULL, &live) != AVM_OK) return NULL;
  return live;
}

/* (1) and (3): a handle destroyed while other threads use it; `closer_thread` destroys from a
 * thread of its own instead of the main thread. Returns the cycles run. */
static int destroy_while_used(double seconds, int closer_thread) {
  const double end = now_s() + seconds;
  int cycles = 0;
  unsigned seed = 12345u;
  while (now_s() < end || cycles == 0) {
    worker_args push_a, sample_a;
    pthread_t tp, ts, tc;
    closer_args c;
    avm_live* live = create_live();
    CHECK(live != NULL);
    if (live == NULL) return cycles;
    memset(&push_a, 0, sizeof push_a);
    memset(&sample_a, 0, sizeof sample_a);
    push_a.live = sample_a.live = live;
    push_a.until = sample_a.until = now_s() + 30.0; /* refused long before */
    seed = seed * 1103515245u + 12345u;
    c.live = live;
    c.delay_ms = (int)((seed >> 16) % 40u);
    CHECK(pthread_create(&tp, NULL, pusher, &push_a) == 0);
    CHECK(pthread_create(&ts, NULL, sampler, &sample_a) == 0);
    if (closer_thread) {
      CHECK(pthread_create(&tc, NULL, closer, &c) == 0);
      pthread_join(tc, NULL);
    } else {
      closer(&c);
    }
    pthread_join(tp, NULL);
    pthread_join(ts, NULL);
    /* Both threads were stopped by the destroy: refused with the message, nothing else. */
    CHECK(push_a.refused == 1 && push_a.said_destroyed);
    CHECK(sample_a.refused == 1 && sample_a.said_destroyed);
    CHECK(push_a.other == 0 && sample_a.other == 0);
    avm_live_destroy(live); /* twice: a no-op */
    ++cycles;
  }
  return cycles;
}

/* (2): two pushers on one handle; every accepted push counted once. */
static long two_pushers(double seconds) {
  worker_args a[2];
  pthread_t t[2];
  avm_live_stats st;
  int i;
  avm_live* live = create_live();
  CHECK(live != NULL);
  if (live == NULL) return 0;
  for (i = 0; i < 2; ++i) {
    memset(&a[i], 0, sizeof a[i]);
    a[i].live = live;
    a[i].index = i;
    a[i].until = now_s() + seconds;
    CHECK(pthread_create(&t[i], NULL, pusher, &a[i]) == 0);
  }
  for (i = 0; i < 2; ++i) pthread_join(t[i], NULL);
  CHECK(a[0].refused == 0 && a[1].refused == 0 && a[0].other == 0 && a[1].other == 0);
  CHECK(a[0].ok > 0 && a[1].ok > 0);
  CHECK(avm_live_get_stats(live, &st) == AVM_OK);
  CHECK(st.pushed == a[0].ok + a[1].ok);
  CHECK(st.processed + st.dropped <= st.pushed);
  avm_live_destroy(live);
  return a[0].ok + a[1].ok;
}

int main(void) {
  const char* models = getenv("AVATARMAP_MODELS");
  const char* secs = getenv("AVATARMAP_STRESS_SECONDS");
  const double seconds = secs != NULL && atof(secs) > 0 ? atof(secs) : 2.0;
  avm_live* probe;
  int cycles1, cycles3;
  long pushes;
  memset(g_pixels, 128, sizeof g_pixels);
  if (models == NULL || *models == '\0') {
    printf("skipped: set AVATARMAP_MODELS to the converted models\n");
    return SKIP;
  }
  probe = create_live();
  if (probe == NULL) {
    printf("skipped: %s\n", avm_last_create_error()); /* a build without ONNX Runtime */
    return SKIP;
  }
  avm_live_destroy(probe);
  cycles1 = destroy_while_used(seconds, 0);
  pushes = two_pushers(seconds);
  cycles3 = destroy_while_used(seconds, 1);
  printf(
      "destroy during push and sample: %d cycles; two pushers: %ld pushes; push, sample "
      "and destroy from three threads: %d cycles (%.0f s each)\n",
      cycles1, pushes, cycles3, seconds);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
