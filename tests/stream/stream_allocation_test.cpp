// The per-frame path of a VMC stream allocates nothing: building a bundle and sending it, with
// a receiver and without one. The counting operator new (tests/support/counting_new.hpp) is
// included here only, once for the stream_tests executable.
#include <gtest/gtest.h>

#include "avatarmap/stream/vmc_stream.hpp"
#include "support/counting_new.hpp"

namespace avatarmap {
namespace {

// Every blend set, the largest bundle (both: 68 blend values) included.
class stream_allocation : public ::testing::TestWithParam<vmc_blend_set> {};

TEST_P(stream_allocation, send_allocates_nothing) {
  auto stream = std::make_unique<vmc_stream>();
  const vmc_skeleton skeleton = make_vmc_skeleton(make_proxy_skeleton());
  // A closed port: the refusals take the error path too.
  ASSERT_TRUE(stream->open({"127.0.0.1", 9}, skeleton, {}, GetParam()).ok());
  proxy_pose pose;
  pose[bone::left_upper_arm] = glm::angleAxis(0.5f, glm::vec3(0, 0, 1));
  pose[expression::aa] = 0.5f;
  pose[blendshape::jaw_open] = 0.5f;
  stream->send(pose, 0.f);  // warm-up
  const long before = g_allocations.load();
  for (int i = 0; i < 100; ++i) {
    pose.hips_position.y = 0.9f + 0.001f * static_cast<float>(i);
    stream->send(pose, 0.01f * static_cast<float>(i));
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(stream->stats().sent + stream->stats().refused + stream->stats().dropped +
                stream->stats().errors,
            101);
  EXPECT_EQ(stream->encode_failures(), 0);
}

INSTANTIATE_TEST_SUITE_P(sets, stream_allocation,
                         ::testing::Values(vmc_blend_set::vrm0, vmc_blend_set::arkit,
                                           vmc_blend_set::both));

}  // namespace
}  // namespace avatarmap
