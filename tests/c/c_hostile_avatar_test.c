/* Hostile avatars through the C API (issue 8): avm_retargeter_create and avm_clip_write (.glb,
 * .bvh of the rig) on avatars built to crash the loader (20,000 levels of JSON in extras and
 * in VRMC_vrm, a GLB whose chunk lengths lie), to read a file outside the avatar's folder (a
 * buffer URI ../secret.txt, an absolute path, file:) or to slip a wrong rig through (hips node
 * 2^40, a zero scale): an error status (AVM_ERROR_PARSE) and a message naming the avatar and
 * the fault, never a crash; nothing written, an existing output untouched, the secret in no
 * output. The clean avatar of the same shape is retargeted and written. Runs in its own
 * folder (writes files there). Prints "N passed, N failed". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avatarmap/avatarmap.h"
#include "check.h"
#include "test_util.h"

static void write_bytes(const char* path, const char* bytes, size_t n) {
  FILE* f = fopen(path, "wb");
  if (f == NULL) return;
  fwrite(bytes, 1, n, f);
  fclose(f);
}

/* Whole file into a malloc'ed buffer (NUL-terminated; NULL when unreadable). */
static char* read_all(const char* path, size_t* out_size) {
  FILE* f = fopen(path, "rb");
  char* buf = NULL;
  size_t size = 0, cap = 0, got;
  if (f == NULL) return NULL;
  for (;;) {
    if (size + 4096 + 1 > cap) {
      char* bigger;
      cap = (size + 4096 + 1) * 2;
      bigger = (char*)realloc(buf, cap);
      if (bigger == NULL) break;
      buf = bigger;
    }
    got = fread(buf + size, 1, 4096, f);
    if (got == 0) break;
    size += got;
  }
  fclose(f);
  if (buf != NULL) buf[size] = '\0';
  if (out_size != NULL) *out_size = size;
  return buf;
}

static int file_contains(const char* path, const char* text) {
  size_t size = 0, i, n = strlen(text);
  char* buf = read_all(path, &size);
  int found = 0;
  if (buf == NULL) return 0;
  for (i = 0; !found && i + n <= size; ++i) found = memcmp(buf + i, text, n) == 0;
  free(buf);
  return found;
}

/* A VRM 1.0 avatar of three nodes: root > hips > spine, with `hips_extra` in the hips node,
 * `vrm_extra` in VRMC_vrm before "humanoid" (ending with a comma), `hips` as the hips' node
 * index and `extra` appended to the top-level object. Malloc'ed. */
static char* build_avatar(const char* extra, const char* hips, const char* hips_extra,
                          const char* vrm_extra) {
  static const char* fmt =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"name\":\"root\",\"children\":[1]},"
      "{\"name\":\"hips\",\"children\":[2],\"translation\":[0,1,0]%s},"
      "{\"name\":\"spine\",\"translation\":[0,0.1,0]}],"
      "\"extensionsUsed\":[\"VRMC_vrm\"],\"extensions\":{\"VRMC_vrm\":{\"specVersion\":\"1.0\","
      "%s\"humanoid\":{\"humanBones\":{\"hips\":{\"node\":%s},\"spine\":{\"node\":2}}}}}%s}";
  size_t n =
      strlen(fmt) + strlen(extra) + strlen(hips) + strlen(hips_extra) + strlen(vrm_extra) + 1;
  char* out = (char*)malloc(n);
  if (out != NULL) snprintf(out, n, fmt, hips_extra, vrm_extra, hips, extra);
  return out;
}

/* 20,000 nested arrays around 1. Malloc'ed. */
static char* deep_arrays(void) {
  const int depth = 20000;
  char* s = (char*)malloc((size_t)depth * 2 + 2);
  int i;
  if (s == NULL) return NULL;
  for (i = 0; i < depth; ++i) s[i] = '[';
  s[depth] = '1';
  for (i = 0; i < depth; ++i) s[depth + 1 + i] = ']';
  s[2 * depth + 1] = '\0';
  return s;
}

static void put_u32(unsigned char* p, unsigned long v) {
  p[0] = (unsigned char)(v & 255);
  p[1] = (unsigned char)((v >> 8) & 255);
  p[2] = (unsigned char)((v >> 16) & 255);
  p[3] = (unsigned char)((v >> 24) & 255);
}

/* Writes `json` as a GLB (JSON chunk only) to `path`; the header's total length is off by
 * `delta` bytes. */
static void write_glb(const char* path, const char* json, long delta) {
  size_t n = strlen(json), padded = (n + 3) / 4 * 4, total = 20 + padded;
  unsigned char* b = (unsigned char*)malloc(total);
  if (b == NULL) return;
  memcpy(b, "glTF", 4);
  put_u32(b + 4, 2);
  put_u32(b + 8, (unsigned long)((long)total + delta));
  put_u32(b + 12, (unsigned long)padded);
  memcpy(b + 16, "JSON", 4);
  memcpy(b + 20, json, n);
  memset(b + 20 + n, ' ', padded - n);
  write_bytes(path, (const char*)b, total);
  free(b);
}

static const char* k_secret = "TOP-SECRET-c4e1b2";

/* `avatar` must be refused by avm_retargeter_create and by avm_clip_write (.glb and .bvh)
 * with AVM_ERROR_PARSE and a message naming it and containing `words`; keep.glb unchanged. */
static void expect_refused(avm_clip* clip, const char* avatar, const char* words) {
  avm_retargeter* r = NULL;
  char err[1024];
  avm_status s = avm_retargeter_create(avatar, NULL, &r);
  CHECK(s == AVM_ERROR_PARSE);
  CHECK(r == NULL);
  CHECK(contains(avm_last_create_error(), avatar));
  CHECK(contains(avm_last_create_error(), words));
  if (!contains(avm_last_create_error(), words))
    fprintf(stderr, "  %s: %s\n", avatar, avm_last_create_error());
  s = avm_clip_write(clip, "new.glb", 30.0, avatar, NULL, err, sizeof err);
  CHECK(s == AVM_ERROR_PARSE);
  CHECK(contains(err, words));
  CHECK(!file_exists("new.glb"));
  s = avm_clip_write(clip, "new.bvh", 30.0, avatar, NULL, err, sizeof err);
  CHECK(s == AVM_ERROR_PARSE);
  CHECK(!file_exists("new.bvh"));
  s = avm_clip_write(clip, "keep.glb", 30.0, avatar, NULL, err, sizeof err);
  CHECK(s != AVM_OK);
  CHECK(file_contains("keep.glb", "the user's old output"));
}

int main(void) {
  avm_clip* clip = NULL;
  avm_pose p;
  avm_retargeter* r = NULL;
  char err[1024];
  char* deep = deep_arrays();
  char* text;
  char extra[512];
  int i;
  const char* uris[4];
  const char* words[4];

  CHECK(deep != NULL);
  if (deep == NULL) return 1;
  CHECK(avm_clip_create(&clip) == AVM_OK);
  for (i = 0; i < 10; ++i) {
    rest_pose(i / 30.0, &p);
    p.rotations[AVM_BONE_SPINE][0] = 0.05f * (float)i;
    p.rotations[AVM_BONE_SPINE][3] = 1.f;
    CHECK(avm_clip_add(clip, &p) == AVM_OK);
  }
  write_bytes("secret.txt", k_secret, strlen(k_secret));
  write_bytes("keep.glb", "the user's old output", 21);
  remove("new.glb");
  remove("new.bvh");
  /* Avatars live in av/, the secret one folder up. */
  CHECK(system("mkdir -p av") == 0);

  /* The control: the clean avatar works. */
  text = build_avatar("", "1", "", "");
  write_bytes("av/clean.gltf", text, strlen(text));
  free(text);
  CHECK(avm_retargeter_create("av/clean.gltf", NULL, &r) == AVM_OK);
  /* Indices a caller passes are checked too. */
  CHECK(avm_retargeter_joint_name(r, 1) != NULL);
  CHECK(avm_retargeter_joint_name(r, 3) == NULL);
  CHECK(avm_retargeter_joint_name(r, -1) == NULL);
  CHECK(avm_retargeter_joint_name(r, 2147483647) == NULL);
  CHECK(avm_retargeter_joint_parent(r, 1 << 30) == -1);
  CHECK(avm_retargeter_bone_joint(r, AVM_BONE_COUNT) == -1);
  CHECK(avm_retargeter_bone_joint(r, -2147483647 - 1) == -1);
  avm_retargeter_destroy(r);
  r = NULL;
  CHECK(avm_clip_write(clip, "clean.glb", 30.0, "av/clean.gltf", NULL, err, sizeof err) == AVM_OK);
  CHECK(avm_clip_write(clip, "clean.bvh", 30.0, "av/clean.gltf", NULL, err, sizeof err) == AVM_OK);

  /* Deep nesting: in the root's extras (text glTF), inside VRMC_vrm (GLB). */
  text = (char*)malloc(strlen(deep) + 32);
  if (text != NULL) {
    char* avatar;
    snprintf(text, strlen(deep) + 32, ",\"extras\":%s", deep);
    avatar = build_avatar(text, "1", "", "");
    write_bytes("av/deep_extras.gltf", avatar, strlen(avatar));
    free(avatar);
    snprintf(text, strlen(deep) + 32, "\"meta\":%s,", deep);
    avatar = build_avatar("", "1", "", text);
    write_glb("av/deep_vrmc.vrm", avatar, 0);
    free(avatar);
    free(text);
  }
  expect_refused(clip, "av/deep_extras.gltf", "deeper than 128 levels");
  expect_refused(clip, "av/deep_vrmc.vrm", "deeper than");

  /* A GLB header that claims more bytes than the file has. */
  text = build_avatar("", "1", "", "");
  write_glb("av/long.vrm", text, 64);
  free(text);
  expect_refused(clip, "av/long.vrm", "truncated");

  /* URIs out of the folder. */
  uris[0] = "../secret.txt";
  words[0] = "leaves the avatar's folder";
  uris[1] = "%2e%2e/secret.txt";
  words[1] = "leaves the avatar's folder";
  uris[2] = "file:///etc/passwd";
  words[2] = "scheme (file:)";
  uris[3] = "/etc/passwd";
  words[3] = "absolute path";
  for (i = 0; i < 4; ++i) {
    char* avatar;
    snprintf(extra, sizeof extra, ",\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%d}]", uris[i],
             (int)strlen(k_secret));
    avatar = build_avatar(extra, "1", "", "");
    write_bytes("av/uri.gltf", avatar, strlen(avatar));
    free(avatar);
    expect_refused(clip, "av/uri.gltf", words[i]);
    snprintf(extra, sizeof extra, ",\"images\":[{\"uri\":\"%s\"}]", uris[i]);
    avatar = build_avatar(extra, "1", "", "");
    write_bytes("av/image.gltf", avatar, strlen(avatar));
    free(avatar);
    expect_refused(clip, "av/image.gltf", words[i]);
  }
  CHECK(!file_contains("clean.glb", k_secret));

  /* Wrong rigs: hips node 2^40 (would be node 0 when truncated to 32 bits), a zero scale. */
  text = build_avatar("", "1099511627776", "", "");
  write_bytes("av/hips40.gltf", text, strlen(text));
  free(text);
  expect_refused(clip, "av/hips40.gltf", "1099511627776");
  text = build_avatar("", "1", ",\"scale\":[0,1,1]", "");
  write_bytes("av/zero.gltf", text, strlen(text));
  free(text);
  expect_refused(clip, "av/zero.gltf", "zero");
  CHECK(contains(avm_last_create_error(), "'hips'"));

  avm_clip_destroy(clip);
  free(deep);
  printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
