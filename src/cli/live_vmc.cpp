#include "cli/live_vmc.hpp"

#include <algorithm>
#include <optional>
#include <string>

#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/stream/host_port.hpp"
#include "avatarmap/stream/vmc_skeleton.hpp"

namespace avatarmap::cli {

const char* const k_live_vmc_help =
    "  --vmc HOST[:PORT]     also stream every output pose to a VMC protocol receiver\n"
    "                        (VSeeFace, VMagicMirror, Warudo, EVMC4U; docs/vmc.md): one OSC\n"
    "                        bundle per output frame over UDP, port 39539 unless given;\n"
    "                        [IPV6]:PORT for IPv6. Never slows the loop: a receiver that is\n"
    "                        not running only shows in the summary (refused). Latency from\n"
    "                        a frame's arrival to the packet: median ~23 ms, p95 ~50 ms at\n"
    "                        --fps 60 on a 2-core machine (body only)\n"
    "  --avatar FILE         the receiver's model (.vrm, .glb): its bones and rest positions\n"
    "                        are sent (default: every bone of a 1.70 m proxy skeleton)\n"
    "  --vmc-blendshapes SET the face's /VMC/Ext/Blend/Val names: vrm0 (default: the VRM 0.x\n"
    "                        presets A I U E O, Blink, Blink_L/R, LookUp..., Joy Angry Sorrow\n"
    "                        Fun, which every VRM model has), arkit (ARKit's 52 by Apple's\n"
    "                        names, for Perfect Sync avatars) or both\n";

int live_vmc::read_options(args& a) {
  given_ = a.value("--vmc", destination_);
  const bool avatar = a.value("--avatar", avatar_path_);
  std::string blends;
  const bool blends_given = a.value("--vmc-blendshapes", blends);
  if (!a.error().empty()) return 0;  // the caller reports the scanner's error
  if (blends_given) {
    const std::optional<vmc_blend_set> set = vmc_blend_set_from_name(blends);
    if (!set) {
      std::fprintf(stderr,
                   "avatarmap live: --vmc-blendshapes takes vrm0, arkit or both, got '%s'\n",
                   blends.c_str());
      return 2;
    }
    if (!given_) {
      std::fprintf(stderr,
                   "avatarmap live: --vmc-blendshapes chooses what --vmc sends: use it with --vmc "
                   "HOST[:PORT]\n");
      return 2;
    }
    blends_ = *set;
  }
  if (avatar && !given_) {
    std::fprintf(stderr,
                 "avatarmap live: --avatar gives the VMC receiver's model: use it with --vmc "
                 "HOST[:PORT]\n");
    return 2;
  }
  if (avatar && avatar_path_.empty()) {
    std::fprintf(stderr, "avatarmap live: --avatar needs a file (.vrm, .glb, .gltf)\n");
    return 2;
  }
  return 0;
}

int live_vmc::open() {
  if (!given_) return 0;
  host_port to;
  status st = parse_host_port(destination_, k_vmc_default_port, to);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: --vmc %s\n", st.message().c_str());
    return 2;
  }
  vmc_skeleton skeleton;
  if (avatar_path_.empty()) {
    skeleton = make_vmc_skeleton(make_proxy_skeleton());
    rest_source_ = "the 1.70 m proxy skeleton";
  } else {
    bound_avatar avatar;
    st = bind_avatar(avatar_path_, bind_avatar_options{}, avatar);
    if (avatar.failed_step == bind_avatar_step::select)
      st = st.with_message(st.message() +
                           "\nFor --vmc, --avatar takes a VRM model or a rig one of the shipped "
                           "tables fits; leave it out to send the proxy skeleton's proportions.");
    // The performer's standing hips height is not known live: the solver's default stands in.
    if (st.ok())
      st = make_vmc_skeleton(avatar.rig, avatar.binding, k_default_hips_height, skeleton);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap live: --avatar: %s\n", st.message().c_str());
      return 1;
    }
    rest_source_ = avatar_path_;
  }
  stream_ = std::make_unique<vmc_stream>();
  st = stream_->open(to, skeleton, {}, blends_);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: --vmc: %s\n", st.message().c_str());
    stream_.reset();
    return 1;
  }
  if (!stream_->warning().empty())
    std::fprintf(stderr, "avatarmap live: --vmc: warning: %s\n", stream_->warning().c_str());
  return 0;
}

void live_vmc::send(const proxy_pose& pose, const live_output_report& report) {
  if (!stream_) return;
  stream_->send(pose, static_cast<float>(pose.t));
  if (!report.carries_new_frame) return;
  latencies_.add(
      std::chrono::duration<double, std::milli>(clock_type::now() - report.pushed_at).count());
}

void live_vmc::print_summary(std::FILE* out) const {
  if (!stream_) return;
  const udp_send_stats& s = stream_->stats();
  std::fprintf(out,
               "vmc: %ld bundles sent to %s (%d bones, %d blend values (%s), %.1f KB each; rest "
               "positions from %s), %ld dropped, %ld refused (no receiver), %ld errors\n",
               s.sent, stream_->address().c_str(), stream_->bone_messages(),
               stream_->blend_messages(),
               std::string(vmc_blend_set_name(stream_->blend_set())).c_str(),
               static_cast<double>(stream_->last_bundle_bytes()) / 1024.0, rest_source_.c_str(),
               s.dropped, s.refused, s.errors + stream_->encode_failures());
  if (latencies_.count() == 0) return;
  const latency_summary l = latencies_.summary();
  std::fprintf(out,
               "vmc latency (frame delivered -> first packet with its pose, %ld frames): median "
               "%.1f ms, p95 %.1f, max %.1f\n",
               l.kept, l.p50_ms, l.p95_ms, l.max_ms);
}

}  // namespace avatarmap::cli
