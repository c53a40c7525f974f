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
    "                        [IPV6]:PORT for IPv6. Repeatable, one receiver per person: the\n"
    "                        k-th --vmc receives the k-th person's slot (with one person only\n"
    "                        the first; people beyond the last --vmc are not sent). Never\n"
    "                        slows the loop: a receiver that is not running only shows in the\n"
    "                        summary (refused). Latency from a frame's arrival to the packet:\n"
    "                        median ~23 ms, p95 ~50 ms at --fps 60 on a 2-core machine (body\n"
    "                        only, one person)\n"
    "  --avatar FILE         the receivers' model (.vrm, .glb): its bones and rest positions\n"
    "                        are sent (default: every bone of a 1.70 m proxy skeleton)\n"
    "  --vmc-blendshapes SET the face's /VMC/Ext/Blend/Val names: vrm0 (default: the VRM 0.x\n"
    "                        presets A I U E O, Blink, Blink_L/R, LookUp..., Joy Angry Sorrow\n"
    "                        Fun, which every VRM model has), arkit (ARKit's 52 by Apple's\n"
    "                        names, for Perfect Sync avatars) or both\n";

int live_vmc::read_options(args& a) {
  std::string destination;
  while (a.value("--vmc", destination)) given_.push_back(destination);  // repeatable: slot k
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
    if (given_.empty()) {
      std::fprintf(stderr,
                   "avatarmap live: --vmc-blendshapes chooses what --vmc sends: use it with --vmc "
                   "HOST[:PORT]\n");
      return 2;
    }
    blends_ = *set;
  }
  if (avatar && given_.empty()) {
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
  if (given_.empty()) return 0;
  // Every destination is parsed before anything is loaded or resolved: a malformed one is a
  // usage error whichever --vmc it is.
  std::vector<host_port> to(given_.size());
  for (std::size_t k = 0; k < given_.size(); ++k) {
    const status st = parse_host_port(given_[k], k_vmc_default_port, to[k]);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap live: --vmc %s\n", st.message().c_str());
      return 2;
    }
  }
  vmc_skeleton skeleton;
  if (avatar_path_.empty()) {
    skeleton = make_vmc_skeleton(make_proxy_skeleton());
    rest_source_ = "the 1.70 m proxy skeleton";
  } else {
    bound_avatar avatar;
    status st = bind_avatar(avatar_path_, bind_avatar_options{}, avatar);
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
  std::vector<std::unique_ptr<destination>> opened;
  for (std::size_t k = 0; k < to.size(); ++k) {
    auto d = std::make_unique<destination>();
    d->stream = std::make_unique<vmc_stream>();
    const status st = d->stream->open(to[k], skeleton, {}, blends_);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap live: --vmc: %s\n", st.message().c_str());
      return 1;
    }
    if (!d->stream->warning().empty())
      std::fprintf(stderr, "avatarmap live: --vmc: warning: %s\n", d->stream->warning().c_str());
    opened.push_back(std::move(d));
  }
  destinations_ = std::move(opened);
  return 0;
}

void live_vmc::send(const proxy_pose& pose, const live_output_report& report) {
  if (destinations_.empty()) return;
  const int slot = report.slot;
  if (slot < 0 || slot >= static_cast<int>(destinations_.size())) {
    ++unsent_;
    unsent_people_ = std::max(unsent_people_, slot + 1 - static_cast<int>(destinations_.size()));
    if (!unsent_said_) {
      unsent_said_ = true;
      std::fprintf(stderr,
                   "avatarmap live: --vmc: a person in slot %d has no receiver (%d --vmc given, "
                   "one per person in slot order): people beyond the last --vmc are not sent\n",
                   slot, static_cast<int>(destinations_.size()));
    }
    return;
  }
  destination& d = *destinations_[static_cast<std::size_t>(slot)];
  d.stream->send(pose, static_cast<float>(pose.t));
  if (!report.carries_new_frame) return;
  d.latencies.add(
      std::chrono::duration<double, std::milli>(clock_type::now() - report.pushed_at).count());
}

void live_vmc::print_summary(std::FILE* out) const {
  const bool several = destinations_.size() > 1;
  for (std::size_t k = 0; k < destinations_.size(); ++k) {
    const vmc_stream& stream = *destinations_[k]->stream;
    const udp_send_stats& s = stream.stats();
    const std::string whose = several ? " for slot " + std::to_string(k) : std::string();
    std::fprintf(out,
                 "vmc: %ld bundles sent to %s%s (%d bones, %d blend values (%s), %.1f KB each; "
                 "rest positions from %s), %ld dropped, %ld refused (no receiver), %ld errors\n",
                 s.sent, stream.address().c_str(), whose.c_str(), stream.bone_messages(),
                 stream.blend_messages(),
                 std::string(vmc_blend_set_name(stream.blend_set())).c_str(),
                 static_cast<double>(stream.last_bundle_bytes()) / 1024.0, rest_source_.c_str(),
                 s.dropped, s.refused, s.errors + stream.encode_failures());
    const latency_stats& latencies = destinations_[k]->latencies;
    if (latencies.count() == 0) continue;
    const latency_summary l = latencies.summary();
    std::fprintf(out,
                 "vmc latency%s (frame delivered -> first packet with its pose, %ld frames): "
                 "median %.1f ms, p95 %.1f, max %.1f\n",
                 whose.c_str(), l.kept, l.p50_ms, l.p95_ms, l.max_ms);
  }
  if (unsent_ > 0)
    std::fprintf(out,
                 "vmc: %ld poses of %d more people not sent (one --vmc per person; %d given)\n",
                 unsent_, unsent_people_, static_cast<int>(destinations_.size()));
}

}  // namespace avatarmap::cli
