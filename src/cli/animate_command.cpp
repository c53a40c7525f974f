// `avatarmap animate VIDEO --avatar A -o OUT`: capture and convert chained in one command.
// The landmarks go to a temporary file (or --keep-landmarks PATH), which `convert` then solves
// and retargets; both stages keep their own options and messages.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/jobs/clip_output.hpp"
#include "cli/capture_setup.hpp"
#include "cli/commands.hpp"
#include "common/atomic_file.hpp"

namespace avatarmap::cli {
namespace {

const char* k_animate_help =
    "Usage: avatarmap animate VIDEO -o OUT [--avatar AVATAR] [options]\n"
    "\n"
    "Video in, animation out, in one command: `avatarmap capture` (body, hands and face by\n"
    "default) followed by `avatarmap convert` on its landmarks.\n"
    "OUT: *.vrma (VRM Animation), *.glb (AVATAR with the motion), *.bvh (AVATAR's rig, or the\n"
    "proxy skeleton without --avatar), *.pose.jsonl\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH        the animation (required; written atomically)\n"
    "  --avatar FILE            the avatar to drive (.vrm, .glb, .gltf; required for .glb)\n"
    "  --keep-landmarks PATH    keep the captured landmarks (*.landmarks.jsonl) there\n"
    "  --overlay PATH           as for `capture`\n"
    "  --rig, --bind, --fps, --ground, --no-root-motion, --filter, --smoothing, --mirror\n"
    "                           as for `convert`\n"
    "  --body-only              neither hands nor face (same as --no-hands --no-face)\n"
    "  --quiet                  no progress and no summaries\n"
    "\n"
    "Capture options (--hands and --face are on unless turned off):\n";

// Options of each stage: name -> takes a value.
struct option_spec {
  const char* name;
  bool has_value;
};
// Every estimator option `capture` takes (capture_setup's parse_estimator_options), which
// `animate --help` lists; tests/cli/cli_test.sh checks each listed option is accepted.
constexpr option_spec k_capture_options[] = {
    {"--model", true},     {"--hand-model", true}, {"--threads", true},   {"--models", true},
    {"--overlay", true},   {"--static", false},    {"--hands", false},    {"--no-hands", false},
    {"--face", false},     {"--no-face", false},   {"--mirrored", false}, {"--progress", false},
    {"--precision", true}, {"--lanes", true},      {"--spin", false},
};
constexpr option_spec k_convert_options[] = {
    {"--avatar", true},          {"--rig", true},       {"--bind", true},       {"--fps", true},
    {"--filter", true},          {"--smoothing", true}, {"--image-size", true}, {"--ground", false},
    {"--no-root-motion", false}, {"--mirror", false},
};

// Whether `arg` is option `o` ("--name" or "--name=value").
bool is_option(const std::string& arg, const option_spec& o) {
  const std::string n = o.name;
  return arg == n || (o.has_value && arg.rfind(n + "=", 0) == 0);
}

}  // namespace

int run_animate(int argc, char** argv) {
  std::vector<std::string> cap = {"avatarmap", "capture"};
  std::vector<std::string> conv = {"avatarmap", "convert"};
  std::string out_path, keep, input;
  bool quiet = false, body_only = false, hands_given = false, face_given = false;
  for (int i = 2; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--help" || s == "-h") {
      std::fputs(k_animate_help, stdout);
      std::fputs(k_estimator_options_help, stdout);
      return 0;
    }
    auto take_value = [&](std::string& dst) {
      const size_t eq = s.find('=');
      if (eq != std::string::npos && s.rfind("--", 0) == 0) {
        dst = s.substr(eq + 1);
        return true;
      }
      if (i + 1 >= argc) return false;
      dst = argv[++i];
      return true;
    };
    if (s == "-o" || s == "--output" || s.rfind("--output=", 0) == 0) {
      if (!take_value(out_path)) {
        std::fprintf(stderr, "avatarmap animate: %s needs a value\n", s.c_str());
        return 2;
      }
      continue;
    }
    if (s == "--keep-landmarks" || s.rfind("--keep-landmarks=", 0) == 0) {
      if (!take_value(keep)) {
        std::fprintf(stderr, "avatarmap animate: --keep-landmarks needs a path\n");
        return 2;
      }
      continue;
    }
    if (s == "--quiet") {
      quiet = true;
      continue;
    }
    if (s == "--body-only") {
      body_only = true;
      continue;
    }
    bool matched = false;
    for (const option_spec& o : k_capture_options) {
      if (!is_option(s, o)) continue;
      matched = true;
      hands_given |= s == "--hands" || s == "--no-hands";
      face_given |= s == "--face" || s == "--no-face";
      cap.push_back(s);
      if (o.has_value && s.find('=') == std::string::npos) {
        if (i + 1 >= argc) {
          std::fprintf(stderr, "avatarmap animate: %s needs a value\n", s.c_str());
          return 2;
        }
        cap.push_back(argv[++i]);
      }
    }
    for (const option_spec& o : k_convert_options) {
      if (matched || !is_option(s, o)) continue;
      matched = true;
      conv.push_back(s);
      if (o.has_value && s.find('=') == std::string::npos) {
        if (i + 1 >= argc) {
          std::fprintf(stderr, "avatarmap animate: %s needs a value\n", s.c_str());
          return 2;
        }
        conv.push_back(argv[++i]);
      }
    }
    if (matched) continue;
    if (s.rfind("-", 0) == 0 && s != "-") {
      std::fprintf(stderr, "avatarmap animate: unknown option %s (see --help)\n", s.c_str());
      return 2;
    }
    if (!input.empty()) {
      std::fprintf(stderr, "avatarmap animate: give exactly one video (see --help)\n");
      return 2;
    }
    input = s;
  }
  if (input.empty() || out_path.empty()) {
    std::fprintf(stderr, "avatarmap animate: %s\n",
                 input.empty() ? "give the video to animate from (see --help)"
                               : "give the output with -o OUT (.vrma, .glb, .bvh, .pose.jsonl)");
    return 2;
  }
  // The output is checked before the capture, which can take minutes (convert checks it again).
  const clip_format_info* format = nullptr;
  if (status st = clip_format_for(out_path, format); !st.ok()) {
    std::fprintf(stderr, "avatarmap animate: %s\n", st.message().c_str());
    return 2;
  }
  bool has_avatar = false;
  for (const std::string& c : conv) has_avatar |= c == "--avatar" || c.rfind("--avatar=", 0) == 0;
  if (format->needs_avatar && !has_avatar) {
    std::fprintf(stderr, "avatarmap animate: .glb output needs --avatar AVATAR\n");
    return 2;
  }
  if (body_only) {
    cap.push_back("--no-hands");
    cap.push_back("--no-face");
  } else {
    if (!hands_given) cap.push_back("--hands");
    if (!face_given) cap.push_back("--face");
  }

  // The landmarks: --keep-landmarks, else a private temporary file removed at the end, or by
  // the signal handlers (main.cpp) when the run is interrupted.
  std::string landmarks = keep;
  bool temporary = false;
  std::unique_ptr<io_detail::temp_file_registration> registration;
  if (landmarks.empty()) {
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    if (ec) dir = ".";
    std::string tmpl = (dir / "avatarmap-animate-XXXXXX.landmarks.jsonl").string();
    const int fd = mkstemps(tmpl.data(), static_cast<int>(std::string(".landmarks.jsonl").size()));
    if (fd < 0) {
      std::fprintf(stderr, "avatarmap animate: cannot create a temporary file in %s: %s\n",
                   dir.string().c_str(), std::strerror(errno));
      return 1;
    }
    registration = std::make_unique<io_detail::temp_file_registration>(tmpl);
    close(fd);
    landmarks = tmpl;
    temporary = true;
  }
  cap.insert(cap.end(), {input, "-o", landmarks});
  conv.insert(conv.end(), {landmarks, "-o", out_path});
  if (quiet) {
    cap.push_back("--quiet");
    conv.push_back("--quiet");
  }
  auto run = [](std::vector<std::string>& v, int (*fn)(int, char**)) {
    std::vector<char*> p;
    for (std::string& s : v) p.push_back(s.data());
    p.push_back(nullptr);
    return fn(static_cast<int>(v.size()), p.data());
  };
  int rc = run(cap, run_capture);
  if (rc == 0) rc = run(conv, run_convert);
  if (temporary) std::remove(landmarks.c_str());
  return rc;
}

}  // namespace avatarmap::cli
