// Known answers of avatarmap/core/spaces.hpp: MediaPipe world / image space -> VRM space.
#include "avatarmap/core/spaces.hpp"

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "avatarmap/landmarks/pose_landmark.hpp"

namespace avatarmap {
namespace {

TEST(spaces, world_to_vrm_known_answers) {
  // x right stays, y down becomes up, z away from the camera becomes toward it.
  EXPECT_EQ(world_to_vrm({1.f, 0.f, 0.f}), glm::vec3(1.f, 0.f, 0.f));
  EXPECT_EQ(world_to_vrm({0.f, 1.f, 0.f}), glm::vec3(0.f, -1.f, 0.f));
  EXPECT_EQ(world_to_vrm({0.f, 0.f, 1.f}), glm::vec3(0.f, 0.f, -1.f));
  EXPECT_EQ(world_to_vrm({0.1f, -0.5f, 0.2f}), glm::vec3(0.1f, 0.5f, -0.2f));
  // A shoulder above the hips (smaller MediaPipe y) is higher in VRM space.
  EXPECT_GT(world_to_vrm({0.f, -0.5f, 0.f}).y, world_to_vrm({0.f, 0.f, 0.f}).y);
  // Right-handed in, right-handed out: (x, -y, -z) is a rotation (det +1), not a reflection.
  const glm::vec3 ex = world_to_vrm({1.f, 0.f, 0.f}), ey = world_to_vrm({0.f, 1.f, 0.f}),
                  ez = world_to_vrm({0.f, 0.f, 1.f});
  EXPECT_FLOAT_EQ(glm::dot(glm::cross(ex, ey), ez), 1.f);
}

TEST(spaces, image_to_vrm_pixels_known_answers) {
  const float w = 1280.f, h = 720.f;
  EXPECT_EQ(image_to_vrm_pixels({0.f, 0.f, 0.f}, w, h), glm::vec3(0.f));
  EXPECT_EQ(image_to_vrm_pixels({0.5f, 0.25f, 0.1f}, w, h), glm::vec3(640.f, -180.f, -128.f));
  EXPECT_EQ(image_to_vrm_pixels({1.f, 1.f, -0.5f}, w, h), glm::vec3(1280.f, -720.f, 640.f));
  // Aspect ratio: a 45-degree segment in pixels is 45 degrees after conversion, whereas the
  // normalised coordinates would say otherwise.
  const glm::vec3 a = image_to_vrm_pixels({0.4f, 0.5f, 0.f}, w, h);
  const glm::vec3 b = image_to_vrm_pixels({0.4f + 0.1f, 0.5f - 0.1f * w / h, 0.f}, w, h);
  EXPECT_NEAR(b.x - a.x, b.y - a.y, 1e-3f);
}

// In a raw (non-mirrored) image a person facing the camera has their left side at larger x;
// in VRM space the avatar's left is +X.
TEST(spaces, persons_left_maps_to_vrm_plus_x) {
  const glm::vec3 left_shoulder_img(0.62f, 0.40f, -0.1f);  // larger x
  const glm::vec3 right_shoulder_img(0.38f, 0.41f, -0.1f);
  const glm::vec3 l = image_to_vrm_pixels(left_shoulder_img, 640.f, 480.f);
  const glm::vec3 r = image_to_vrm_pixels(right_shoulder_img, 640.f, 480.f);
  EXPECT_GT(l.x - r.x, 0.f);
  // Same for world landmarks (x toward image right).
  EXPECT_GT(world_to_vrm({0.18f, -0.45f, 0.f}).x - world_to_vrm({-0.18f, -0.45f, 0.f}).x, 0.f);
  // MediaPipe's convention: odd pose indices are the person's left.
  EXPECT_EQ(idx(pose_landmark::left_shoulder) % 2, 1);
  EXPECT_EQ(idx(pose_landmark::right_shoulder) % 2, 0);
}

}  // namespace
}  // namespace avatarmap
