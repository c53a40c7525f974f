// A VMC protocol stream (docs/vmc.md): each send() turns a proxy pose into one VMC bundle
// (stream/vmc_bundle.hpp) in a buffer the stream owns and hands it to a non-blocking UDP sender
// (stream/udp_sender.hpp). Receivers (VSeeFace, VMagicMirror, Warudo, EVMC4U) listen on UDP
// port 39539 unless told otherwise. send() never blocks and never allocates.
// Thread-safety: one thread sends; stats() is read by it or after it stopped.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/foot_lock.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/stream/host_port.hpp"
#include "avatarmap/stream/osc_writer.hpp"
#include "avatarmap/stream/udp_sender.hpp"
#include "avatarmap/stream/vmc_bundle.hpp"
#include "avatarmap/stream/vmc_skeleton.hpp"

namespace avatarmap {

/// The port VMC receivers listen on by default.
inline constexpr int k_vmc_default_port = 39539;

class vmc_stream {
 public:
  vmc_stream() : writer_(buffer_.data(), buffer_.size()) {}
  vmc_stream(const vmc_stream&) = delete;
  vmc_stream& operator=(const vmc_stream&) = delete;

  /// Resolves `to` and keeps `skeleton` (copied). `foot_lock` (docs/foot-locking.md): planted
  /// feet (proxy_pose::foot_contact) are locked on the 1.70 m proxy skeleton before each pose
  /// is sent, the anchors kept from one send() to the next; enabled = false sends the poses as
  /// given. `blends`: the blend values each bundle carries (vmc_bundle.hpp). Fails as
  /// udp_sender::open does, or (invalid_argument) on invalid foot_lock options.
  status open(const host_port& to, const vmc_skeleton& skeleton,
              const foot_lock_options& foot_lock = {}, vmc_blend_set blends = vmc_blend_set::vrm0);
  void close() { sender_.close(); }
  bool is_open() const { return sender_.is_open(); }

  /// Sends `pose` as one bundle stamped `time` (seconds, /VMC/Ext/T). The stamps sent are
  /// strictly increasing, at least 1 us apart: a `time` less than 1 us after the previous
  /// stamp (a repeated or earlier time) or not finite is sent as the previous stamp + 1 us
  /// (the nearest float32, and at least the next float32 above it; 0 for the first). True when the
  /// kernel took it; a dropped or refused packet is counted (stats()) and the call returns at once.
  bool send(const proxy_pose& pose, float time);

  const udp_send_stats& stats() const { return sender_.stats(); }
  /// Bundles that did not fit the buffer (never expected: counted, not sent).
  long encode_failures() const { return encode_failures_; }
  const std::string& address() const { return sender_.address(); }
  const std::string& warning() const { return sender_.warning(); }
  /// /VMC/Ext/Bone/Pos and /VMC/Ext/Blend/Val messages in each bundle.
  int bone_messages() const { return skeleton_.sent_count; }
  int blend_messages() const { return vmc_blend_count(blends_); }
  vmc_blend_set blend_set() const { return blends_; }
  /// Size in bytes of the last bundle built.
  std::size_t last_bundle_bytes() const { return writer_.size(); }

 private:
  std::array<std::uint8_t, k_vmc_bundle_capacity> buffer_{};
  osc_writer writer_;
  udp_sender sender_;
  vmc_skeleton skeleton_{};
  long encode_failures_ = 0;
  vmc_blend_set blends_ = vmc_blend_set::vrm0;
  float last_time_ = -std::numeric_limits<float>::infinity();  // the last /VMC/Ext/T sent
  proxy_foot_lock lock_;
  bool lock_on_ = false;
  proxy_pose locked_;  // scratch: the pose with its feet locked
};

}  // namespace avatarmap
