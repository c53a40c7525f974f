// `avatarmap animate VIDEO -o OUT [--avatar A]`: capture and convert chained in one command.
// The landmarks go to a temporary file (or --keep-landmarks PATH), which `convert` then solves
// and retargets; both stages keep their own options and messages. The flags each stage takes
// are the ones it declares (its option tables and own flags: add_*_command_flag_specs), so
// every flag `capture` or `convert` has is an `animate` flag too.
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
#include "cli/option_flags.hpp"
#include "common/atomic_file.hpp"

namespace avatarmap::cli {
namespace {

const char* k_animate_help =
    "Usage: avatarmap animate VIDEO -o OUT [--avatar AVATAR] [options]\n"
    "\n"
    "Video in, animation out, in one command: `avatarmap capture` (body, hands and face by\n"
    "default) followed by `avatarmap convert` on its landmarks; each takes its own options\n"
    "(below, as each command declares them) and prints its own messages.\n"
    "OUT: *.vrma (VRM Animation), *.glb (AVATAR with the motion; the built-in avatar without\n"
    "--avatar), *.bvh (AVATAR's rig, or the proxy skeleton without --avatar), *.pose.jsonl\n"
    "\n"
    "Options:\n";

// animate's own flags; every other flag is capture's or convert's.
const cli_flag k_animate_flags[] = {
    {"--output", "-o", "PATH", "the animation (required; written atomically)"},
    {"--keep-landmarks", nullptr, "PATH", "keep the captured landmarks (*.landmarks.jsonl) there"},
    {"--body-only", nullptr, nullptr, "neither hands nor face (same as --no-hands --no-face)"},
    {"--quiet", nullptr, nullptr, "no progress and no summaries"},
};

// A flag of `specs` that `arg` is ("--name" or "--name=value"), or nullptr.
const flag_spec* find_flag(const std::vector<flag_spec>& specs, const std::string& arg) {
  for (const flag_spec& f : specs)
    if (arg == f.name || (f.takes_value && arg.rfind(f.name + "=", 0) == 0)) return &f;
  return nullptr;
}

// The flags handed to each stage: capture's and convert's own declarations, less animate's.
struct stage_flags {
  std::vector<flag_spec> own, capture, convert;
  stage_flags() {
    add_flag_specs(k_animate_flags, own);
    std::vector<flag_spec> all;
    add_capture_command_flag_specs(true, all);
    for (flag_spec& f : all)
      if (!find_flag(own, f.name)) capture.push_back(std::move(f));
    all.clear();
    add_convert_command_flag_specs(all);
    for (flag_spec& f : all)
      if (!find_flag(own, f.name) && !find_flag(capture, f.name)) convert.push_back(std::move(f));
  }
};

std::string help_of(const std::vector<flag_spec>& specs) {
  std::string out;
  for (const flag_spec& f : specs) out += f.help;
  return out;
}

}  // namespace

int run_animate(int argc, char** argv) {
  const stage_flags flags;
  std::vector<std::string> cap = {"avatarmap", "capture"};
  std::vector<std::string> conv = {"avatarmap", "convert"};
  std::string out_path, keep, input;
  bool quiet = false, body_only = false, hands_given = false, face_given = false;
  for (int i = 2; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--help" || s == "-h") {
      std::fputs(k_animate_help, stdout);
      std::fputs(help_of(flags.own).c_str(), stdout);
      std::fputs(
          "\nCapture options (as for `avatarmap capture`; hands and face on unless turned "
          "off):\n",
          stdout);
      std::fputs(help_of(flags.capture).c_str(), stdout);
      std::fputs("\nConvert options (as for `avatarmap convert`):\n", stdout);
      std::fputs(help_of(flags.convert).c_str(), stdout);
      return 0;
    }
    // A flag and, when it takes one, its value: "--name value" or "--name=value".
    auto take = [&](const flag_spec& f, std::vector<std::string>* to, std::string* value) {
      std::string v;
      const bool joined = s.size() > f.name.size() && s[f.name.size()] == '=';
      if (f.takes_value && joined) {
        v = s.substr(f.name.size() + 1);
      } else if (f.takes_value) {
        if (i + 1 >= argc) {
          std::fprintf(stderr, "avatarmap animate: %s needs a value\n", s.c_str());
          return false;
        }
        v = argv[++i];
      }
      if (to) {
        to->push_back(f.name);
        if (f.takes_value) to->push_back(v);
      }
      if (value) *value = v;
      return true;
    };
    if (const flag_spec* f = find_flag(flags.own, s)) {
      if (f->name == "--output" || f->name == "-o") {
        if (!take(*f, nullptr, &out_path)) return 2;
      } else if (f->name == "--keep-landmarks") {
        if (!take(*f, nullptr, &keep)) return 2;
      } else if (f->name == "--quiet") {
        quiet = true;
      } else if (f->name == "--body-only") {
        body_only = true;
      }
      continue;
    }
    if (const flag_spec* f = find_flag(flags.capture, s)) {
      hands_given |= f->name == "--hands" || f->name == "--no-hands";
      face_given |= f->name == "--face" || f->name == "--no-face";
      if (!take(*f, &cap, nullptr)) return 2;
      continue;
    }
    if (const flag_spec* f = find_flag(flags.convert, s)) {
      if (!take(*f, &conv, nullptr)) return 2;
      continue;
    }
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
  int rc = run_with_args(cap, run_capture);
  if (rc == 0) rc = run_with_args(conv, run_convert);
  if (temporary) std::remove(landmarks.c_str());
  return rc;
}

}  // namespace avatarmap::cli
