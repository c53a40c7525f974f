// The non-blocking UDP sender against real sockets on the loopback interface: bytes arrive
// intact; no receiver (refused), a receiver that never reads (a port in use by someone who
// does not listen to us) and unresolvable names neither block nor stop the sender.
#include "avatarmap/stream/udp_sender.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "udp_test_receiver.hpp"

namespace avatarmap {
namespace {

using test::udp_receiver;

TEST(udp_sender, datagrams_arrive_intact) {
  udp_receiver rx;
  ASSERT_TRUE(rx.ok());
  udp_sender tx;
  ASSERT_TRUE(tx.open({"127.0.0.1", rx.port()}).ok());
  EXPECT_EQ(tx.address(), "127.0.0.1:" + std::to_string(rx.port()));
  EXPECT_TRUE(tx.warning().empty());
  std::vector<unsigned char> payload(5600);
  for (size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<unsigned char>(i * 7);
  for (int k = 0; k < 3; ++k) {
    payload[0] = static_cast<unsigned char>(k);
    ASSERT_TRUE(tx.send(payload.data(), payload.size()));
    EXPECT_EQ(rx.receive(), payload);
  }
  EXPECT_EQ(tx.stats().sent, 3);
  EXPECT_EQ(tx.stats().dropped + tx.stats().refused + tx.stats().errors, 0);
}

TEST(udp_sender, localhost_resolves_to_ipv4_first) {
  udp_receiver rx;  // IPv4 only, as most VMC receivers
  ASSERT_TRUE(rx.ok());
  udp_sender tx;
  ASSERT_TRUE(tx.open({"localhost", rx.port()}).ok());
  EXPECT_EQ(tx.address().rfind("127.", 0), 0u) << tx.address();
  const char msg[4] = {'/', 'a', 0, 0};
  ASSERT_TRUE(tx.send(msg, sizeof msg));
  EXPECT_EQ(rx.receive().size(), 4u);
}

TEST(udp_sender, ipv6_destination) {
  udp_receiver rx(AF_INET6);
  if (!rx.ok()) GTEST_SKIP() << "no IPv6 loopback on this machine";
  udp_sender tx;
  ASSERT_TRUE(tx.open({"::1", rx.port()}).ok());
  EXPECT_EQ(tx.address(), "[::1]:" + std::to_string(rx.port()));
  const char msg[8] = {'/', 'v', '6', 0, ',', 0, 0, 0};
  ASSERT_TRUE(tx.send(msg, sizeof msg));
  EXPECT_EQ(rx.receive().size(), 8u);
}

TEST(udp_sender, no_receiver_is_counted_not_fatal) {
  int port = 0;
  {
    udp_receiver probe;  // a port that was free a moment ago; nobody listens once it closes
    ASSERT_TRUE(probe.ok());
    port = probe.port();
  }
  udp_sender tx;
  ASSERT_TRUE(tx.open({"127.0.0.1", port}).ok());
  const char msg[4] = {'/', 'a', 0, 0};
  const int n = 200;
  for (int i = 0; i < n; ++i) {
    tx.send(msg, sizeof msg);
    // Let the ICMP "port unreachable" come back between sends (it does within microseconds
    // on loopback); nothing here measures time.
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  const udp_send_stats& s = tx.stats();
  EXPECT_EQ(s.sent + s.refused + s.dropped + s.errors, n);
  EXPECT_GT(s.refused, 0);
  EXPECT_GT(s.sent, 0);  // the sender keeps trying: a receiver that starts later gets packets
  EXPECT_EQ(s.errors, 0);
}

TEST(udp_sender, receiver_that_never_reads_does_not_block) {
  // A port in use by a socket that never reads: its queue fills and the kernel drops the rest
  // there; the sender neither blocks nor fails.
  udp_receiver rx;
  ASSERT_TRUE(rx.ok());
  udp_sender tx;
  ASSERT_TRUE(tx.open({"127.0.0.1", rx.port()}).ok());
  std::vector<unsigned char> payload(5600, 0x2f);
  const int n = 2000;  // ~11 MB, far beyond the receiver's queue
  for (int i = 0; i < n; ++i) tx.send(payload.data(), payload.size());
  const udp_send_stats& s = tx.stats();
  EXPECT_EQ(s.sent + s.dropped, n);
  EXPECT_EQ(s.refused + s.errors, 0);
}

TEST(udp_sender, unresolvable_host_names_the_host) {
  udp_sender tx;
  const status st = tx.open({"no-such-host.invalid", 39539});
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("no-such-host.invalid"), std::string::npos) << st.message();
  EXPECT_FALSE(tx.is_open());
  // Sending on a sender that is not open is counted, not a crash.
  const char msg[4] = {'/', 'a', 0, 0};
  EXPECT_FALSE(tx.send(msg, sizeof msg));
  EXPECT_EQ(tx.stats().errors, 1);
  EXPECT_FALSE(tx.open({"", 39539}).ok());
  EXPECT_FALSE(tx.open({"127.0.0.1", 0}).ok());
}

TEST(udp_sender, oversized_datagram_is_an_error_not_a_crash) {
  udp_receiver rx;
  ASSERT_TRUE(rx.ok());
  udp_sender tx;
  ASSERT_TRUE(tx.open({"127.0.0.1", rx.port()}).ok());
  std::vector<unsigned char> huge(70000, 0);  // over UDP's 65507-byte limit
  EXPECT_FALSE(tx.send(huge.data(), huge.size()));
  EXPECT_EQ(tx.stats().errors, 1);
  const char msg[4] = {'/', 'a', 0, 0};
  EXPECT_TRUE(tx.send(msg, sizeof msg));  // and it goes on
}

}  // namespace
}  // namespace avatarmap
