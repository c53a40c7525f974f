#include "avatarmap/stream/vmc_stream.hpp"

namespace avatarmap {

status vmc_stream::open(const host_port& to, const vmc_skeleton& skeleton,
                        const foot_lock_options& foot_lock) {
  skeleton_ = skeleton;
  encode_failures_ = 0;
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
  if (!write_vmc_bundle(skeleton_, *sent, time, writer_)) {
    ++encode_failures_;
    return false;
  }
  return sender_.send(writer_.data(), writer_.size());
}

}  // namespace avatarmap
