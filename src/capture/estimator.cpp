// The table of estimator backends and the replay backend.
#include "avatarmap/capture/estimator.hpp"

#include "avatarmap/capture/replay_estimator.hpp"
#ifdef AVATARMAP_HAVE_ONNX
#include "capture/onnx/onnx_estimator.hpp"
#endif

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

namespace avatarmap {

bool cpu_has_vnni() {
#if defined(__x86_64__) || defined(__i386__)
  // CPUID leaf 7: subleaf 0 ECX bit 11 is AVX512-VNNI, subleaf 1 EAX bit 4 is AVX-VNNI (read
  // directly: not every compiler's __builtin_cpu_supports knows "avxvnni").
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (!__builtin_cpu_supports("avx2") || __get_cpuid_max(0, nullptr) < 7) return false;
  __cpuid_count(7, 0, a, b, c, d);
  const bool avx512_vnni = (c >> 11) & 1u;
  __cpuid_count(7, 1, a, b, c, d);
  const bool avx_vnni = (a >> 4) & 1u;
  return avx512_vnni || avx_vnni;
#else
  return false;
#endif
}

status replay_estimator::open(const std::string& path, std::unique_ptr<replay_estimator>& out,
                              int max_people) {
  out.reset();
  std::unique_ptr<replay_estimator> r(new replay_estimator());
  r->max_people_ = max_people;
  status s = r->reader_.open(path);
  if (!s.ok()) return s;
  out = std::move(r);
  return {};
}

namespace {
// Removes the parts `args` does not ask for.
void keep_asked_parts(const estimate_args& args, landmark_frame& out) {
  if (!args.body) {
    out.set(frame_part::pose, false);
    out.set(frame_part::pose_world, false);
  }
  if (!args.hands) {
    out.set(frame_part::left_hand, false);
    out.set(frame_part::left_hand_world, false);
    out.set(frame_part::right_hand, false);
    out.set(frame_part::right_hand_world, false);
  }
  if (!args.face) {
    out.set(frame_part::face, false);
    out.face_count = 0;
  }
}
}  // namespace

estimator::people_view replay_estimator::last_people() const {
  if (max_people_ <= 1) return {};
  return {people_.data(), people_count_};
}

status replay_estimator::estimate(const estimate_args& args, landmark_frame& out) {
  if (finished_) return status::error("end of recording");
  // The next line into `f`: false at the end of the recording or on an error (`st` set).
  status st;
  auto first_line = [&](landmark_frame& f) {
    const read_result r = reader_.next(f);
    if (r == read_result::frame) return true;
    if (r == read_result::end) {
      finished_ = true;
      out.clear();
      st = status::error("end of recording");
    } else {
      st = status::failure(reader_.error_code(), reader_.error());
    }
    return false;
  };
  if (max_people_ <= 1) {
    if (!first_line(out)) return st;
    keep_asked_parts(args, out);
    return {};
  }
  // Several people: the lines sharing the first one's time stamp.
  people_count_ = 0;
  if (!has_ahead_ && !first_line(ahead_)) return st;
  people_[people_count_++] = ahead_;
  has_ahead_ = false;
  for (;;) {
    const read_result r = reader_.next(ahead_);
    if (r == read_result::end) break;
    if (r == read_result::error) return status::failure(reader_.error_code(), reader_.error());
    if (ahead_.t != people_[0].t) {
      has_ahead_ = true;
      break;
    }
    if (people_count_ < max_people_) people_[people_count_++] = ahead_;
  }
  // (A version-1 line is person 0: the reader gives it so.)
  for (int i = 0; i < people_count_; ++i) keep_asked_parts(args, people_[i]);
  out = people_[0];
  return {};
}

namespace {
status create_replay(const estimator_options& options, std::unique_ptr<estimator>& out) {
  std::unique_ptr<replay_estimator> r;
  if (options.source.empty())
    return status::error("replay backend: give the recording (*.landmarks.jsonl) as the source");
  status s = replay_estimator::open(options.source, r, options.max_people);
  if (s.ok()) out = std::move(r);
  return s;
}

constexpr estimator_backend k_backends[] = {
    {"replay", "plays a recorded *.landmarks.jsonl file (always built)", &create_replay},
#ifdef AVATARMAP_HAVE_ONNX
    {"onnx",
     "MediaPipe's models under ONNX Runtime; source: the models folder (body; hands and face when "
     "asked)",
     &create_onnx_estimator},
#endif
};
}  // namespace

estimator_backend_list estimator_backends() {
  return {k_backends, static_cast<int>(sizeof(k_backends) / sizeof(k_backends[0]))};
}

status create_estimator(std::string_view name, const estimator_options& options,
                        std::unique_ptr<estimator>& out) {
  out.reset();
  estimator_backend_list list = estimator_backends();
  std::string names;
  for (int i = 0; i < list.count; ++i) {
    if (list.items[i].name == name) return list.items[i].create(options, out);
    if (!names.empty()) names += ", ";
    names += list.items[i].name;
  }
  // "onnx" names a backend that a build without ONNX Runtime lacks: unsupported, not unknown.
  const std::string message =
      "unknown estimator backend '" + std::string(name) + "' (available: " + names + ")";
  return name == "onnx" ? status::unsupported(message) : status::invalid_argument(message);
}

}  // namespace avatarmap
