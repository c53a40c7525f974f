// Example: read a *.landmarks.jsonl file, solve every frame and print the hips rotation.
//
//   example_solve_file FILE.landmarks.jsonl [--mirror]
//
// Prints one line per frame: time, hips rotation {x, y, z, w} (local, VRM 1.0 normalised
// space) and hips position in metres. A malformed line is reported (FILE:LINE: ...) and
// skipped; the exit status is 1 when any line was bad or the file could not be opened.
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/frame_solver.hpp"

int main(int argc, char** argv) {
  namespace am = avatarmap;
  const char* path = nullptr;
  am::solver_options options;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--mirror") == 0) {
      options.mirror = true;
    } else if (path == nullptr) {
      path = argv[i];
    } else {
      path = nullptr;
      break;
    }
  }
  if (path == nullptr) {
    std::fprintf(stderr, "usage: %s FILE.landmarks.jsonl [--mirror]\n", argv[0]);
    return 2;
  }

  am::landmark_reader reader;
  if (am::status st = reader.open(path); !st) {
    std::fprintf(stderr, "error: %s\n", st.message().c_str());
    return 1;
  }
  // The file's image size makes image landmarks isotropic (angles survive any aspect ratio).
  if (reader.header().image_width > 0 && reader.header().image_height > 0) {
    options.image_width = static_cast<float>(reader.header().image_width);
    options.image_height = static_cast<float>(reader.header().image_height);
  }
  if (am::status st = options.validate(); !st) {
    std::fprintf(stderr, "error: %s\n", st.message().c_str());
    return 1;
  }

  // landmark_frame and proxy_pose are fixed-size and large; keep them off the stack.
  auto frame = std::make_unique<am::landmark_frame>();
  auto pose = std::make_unique<am::proxy_pose>();
  am::frame_solver solver(options);
  int frames = 0, bad_lines = 0;
  for (;;) {
    am::read_result r = reader.next(*frame);
    if (r == am::read_result::end) break;
    if (r == am::read_result::error) {
      std::fprintf(stderr, "error: %s\n", reader.error().c_str());
      ++bad_lines;
      continue;
    }
    solver.solve(*frame, *pose);
    float q[4];
    am::store_xyzw((*pose)[am::bone::hips], q);  // {x, y, z, w}: never memcpy a glm::quat
    const glm::vec3& p = pose->hips_position;
    std::printf("t=%9.4f hips rotation [% .5f % .5f % .5f % .5f] position [% .3f % .3f % .3f]\n",
                pose->t, q[0], q[1], q[2], q[3], p.x, p.y, p.z);
    ++frames;
  }
  std::printf("%d frame(s) solved, %d bad line(s)\n", frames, bad_lines);
  return bad_lines == 0 ? 0 : 1;
}
