// /VMC/Ext/T as a receiver sees it: a vmc_stream sends bundles over loopback UDP to a socket
// of the test, each read back with the tests' own OSC decoder (osc_test_reader.hpp). The
// stamps must be strictly increasing whatever times the caller gives: repeated times, times
// closer than float32's step (the live loop's outputs were 1 us apart when a late frame
// arrived: one value was sent twice), times going back, and times that are not finite.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/stream/vmc_stream.hpp"
#include "osc_test_reader.hpp"
#include "udp_test_receiver.hpp"

namespace avatarmap {
namespace {

// Sends one bundle per time and returns the /VMC/Ext/T value of each, as received.
std::vector<float> sent_times(const std::vector<float>& times) {
  test::udp_receiver rx(AF_INET, 4 << 20);  // every bundle of the test queued without loss
  EXPECT_TRUE(rx.ok());
  vmc_stream stream;
  EXPECT_TRUE(stream.open({"127.0.0.1", rx.port()}, make_vmc_skeleton(make_proxy_skeleton())).ok());
  proxy_pose pose;
  std::vector<float> out;
  for (float t : times) {
    EXPECT_TRUE(stream.send(pose, t));
    const std::vector<std::uint8_t> bytes = rx.receive();
    test::osc_packet packet;
    EXPECT_TRUE(test::read_osc_packet(bytes.data(), bytes.size(), packet)) << "t " << t;
    int found = 0;
    for (const test::osc_message& m : packet.messages)
      if (m.address == "/VMC/Ext/T") {
        EXPECT_EQ(m.types, "f");
        if (m.types == "f") out.push_back(m.args[0].f);
        ++found;
      }
    EXPECT_EQ(found, 1) << "one /VMC/Ext/T per bundle";
  }
  return out;
}

TEST(vmc_time, increasing_times_are_sent_as_given) {
  const std::vector<float> times = {0.f, 1.f / 60.f, 2.f / 60.f, 0.5f, 100.25f};
  EXPECT_EQ(sent_times(times), times);
}

TEST(vmc_time, stamps_strictly_increase_whatever_the_times) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  // 100 s + 1 us rounds to 100 s in float32 (its step there is 7.6 us); 2.0000002 is the next
  // float32 above 2, less than 1 us later.
  const std::vector<float> times = {nan,    0.5f,
                                    0.5f,   0.25f,
                                    2.f,    std::nextafter(2.f, 3.f),
                                    100.f,  static_cast<float>(100.000001),
                                    inf,    -inf,
                                    100.5f, 100.5f};
  const std::vector<float> got = sent_times(times);
  ASSERT_EQ(got.size(), times.size());
  EXPECT_EQ(got[0], 0.f) << "a first time that is not finite is sent as 0";
  for (std::size_t i = 1; i < got.size(); ++i) {
    EXPECT_TRUE(std::isfinite(got[i])) << i;
    EXPECT_GT(got[i], got[i - 1]) << "bundle " << i << " (time given " << times[i] << ")";
    // At least 1 us apart (to float32's rounding), and no more than needed.
    const double step = static_cast<double>(got[i]) - static_cast<double>(got[i - 1]);
    EXPECT_GE(step, 0.9e-6) << i;
    if (!(static_cast<double>(times[i]) >= static_cast<double>(got[i - 1]) + 1e-6))
      EXPECT_LE(step, std::max(1.1e-6, 1.01 * (std::nextafter(got[i - 1], 1e9f) - got[i - 1])))
          << i;
  }
  // Six decimals (oscdump's %f) tell every stamp from the previous one.
  for (std::size_t i = 1; i < got.size(); ++i) {
    char a[32], b[32];
    std::snprintf(a, sizeof a, "%f", static_cast<double>(got[i - 1]));
    std::snprintf(b, sizeof b, "%f", static_cast<double>(got[i]));
    EXPECT_STRNE(a, b) << i;
  }
  // Times at least 1 us after the previous stamp are kept.
  EXPECT_EQ(got[1], 0.5f);
  EXPECT_EQ(got[2], static_cast<float>(0.5 + 1e-6));
  EXPECT_EQ(got[4], 2.f);
  EXPECT_EQ(got[5], static_cast<float>(2.0 + 1e-6));
  EXPECT_EQ(got[6], 100.f);
  EXPECT_EQ(got[7], std::nextafter(100.f, 101.f));
  EXPECT_EQ(got[10], 100.5f);
  EXPECT_EQ(got[11], std::nextafter(100.5f, 101.f));
}

}  // namespace
}  // namespace avatarmap
