#include "avatarmap/stream/vmc_stream.hpp"

#include <cmath>
#include <limits>

namespace avatarmap {

namespace {
constexpr double k_min_step = 1e-6;  // seconds between two /VMC/Ext/T stamps, at least
}  // namespace

status vmc_stream::open(const host_port& to, const vmc_skeleton& skeleton,
                        const foot_lock_options& foot_lock, vmc_blend_set blends) {
  skeleton_ = skeleton;
  blends_ = blends;
  encode_failures_ = 0;
  last_time_ = -std::numeric_limits<float>::infinity();
  lock_on_ = foot_lock.enabled;
  if (lock_on_) {
    if (status st = lock_.build(k_proxy_reference_height, foot_lock); !st.ok()) return st;
  }
  return sender_.open(to);
}

bool vmc_stream::send(const proxy_pose& pose, float time) {
  // The buffer holds any bundle (k_vmc_bundle_capacity), so a failure here would be a bug;
  // it is still counted rather than sent half-written.
  const proxy_pose* sent = &pose;
  if (lock_on_) {
    locked_ = pose;  // fixed-size: no allocation
    lock_.apply(locked_);
    sent = &locked_;
  }
  // Receivers read /VMC/Ext/T as the sender's clock: it never repeats nor goes back. A time
  // less than 1 us after the previous stamp (a repeated or earlier time; the live loop's
  // outputs can be 1 us apart, which float32 cannot tell apart beyond 8 s) or not finite is
  // stamped 1 us after the previous one (the float32 nearest, at least the next one above it),
  // so that it differs as a number and as oscdump's six decimals print it.
  if (!std::isfinite(time) || !(static_cast<double>(time) >= last_time_ + k_min_step)) {
    if (!std::isfinite(last_time_)) {
      time = 0.f;
    } else {
      time = static_cast<float>(static_cast<double>(last_time_) + k_min_step);
      if (!(time > last_time_))
        time = std::nextafter(last_time_, std::numeric_limits<float>::max());
    }
  }
  last_time_ = time;
  if (!write_vmc_bundle(skeleton_, *sent, time, writer_, blends_)) {
    ++encode_failures_;
    return false;
  }
  return sender_.send(writer_.data(), writer_.size());
}

}  // namespace avatarmap
