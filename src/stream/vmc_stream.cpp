#include "avatarmap/stream/vmc_stream.hpp"

namespace avatarmap {

status vmc_stream::open(const host_port& to, const vmc_skeleton& skeleton) {
  skeleton_ = skeleton;
  encode_failures_ = 0;
  return sender_.open(to);
}

bool vmc_stream::send(const proxy_pose& pose, float time) {
  // The buffer holds any bundle (k_vmc_bundle_capacity), so a failure here would be a bug;
  // it is still counted rather than sent half-written.
  if (!write_vmc_bundle(skeleton_, pose, time, writer_)) {
    ++encode_failures_;
    return false;
  }
  return sender_.send(writer_.data(), writer_.size());
}

}  // namespace avatarmap
