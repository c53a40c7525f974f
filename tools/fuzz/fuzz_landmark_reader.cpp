// libFuzzer target: the *.landmarks.jsonl reader on arbitrary bytes. Checks that it never
// crashes, always terminates, keeps its documented invariants, and that reading a stream
// in tiny blocks (lines spanning blocks) gives exactly the lines that reading memory gives.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"
#include "io/line_source.hpp"

using namespace avatarmap;

namespace {

void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "invariant failed: %s\n", what);
    std::abort();
  }
}

void read_frames(const char* data, std::size_t size) {
  landmark_reader r;
  if (!r.open_memory(data, size, "<fuzz>")) return;
  landmark_frame f;
  long last_line = 0;
  for (;;) {
    read_result res = r.next(f);
    if (res == read_result::end) break;
    check(r.line() > last_line || res == read_result::error, "line numbers increase");
    last_line = r.line();
    if (res == read_result::error) {
      check(r.error().rfind("<fuzz>:", 0) == 0, "error names the file");
      check(f.parts == 0, "no parts after an error");
      continue;
    }
    check(std::isfinite(f.t), "t finite");
    check(f.parts < (1u << k_frame_part_count), "known parts only");
    if (f.has(frame_part::face))
      check(f.face_count == 468 || f.face_count == 478, "face count 468 or 478");
    else
      check(f.face_count == 0, "no face count without a face");
  }
}

// The same bytes through a FILE* in blocks of 1..16 bytes must split into the same lines.
void compare_line_splitting(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return;
  io_detail::line_source_limits saved = io_detail::default_line_source_limits();
  io_detail::default_line_source_limits() = {1u + data[0] % 16u, 64u + data[1] % 64u};
  const char* text = reinterpret_cast<const char*>(data + 2);
  std::size_t n = size - 2;
  io_detail::line_source mem, file;
  mem.open_memory(text, n);
  std::FILE* fp = n > 0 ? fmemopen(const_cast<char*>(text), n, "rb") : nullptr;
  if (fp) {
    file.open_stream(fp, true);
    std::string_view a, b;
    std::string ea, eb;
    for (;;) {
      auto sa = mem.next(a, ea);
      auto sb = file.next(b, eb);
      check(sa == sb, "same status");
      if (sa == io_detail::line_status::end) break;
      check(mem.line_number() == file.line_number(), "same line number");
      if (sa == io_detail::line_status::line) check(a == b, "same line");
    }
  }
  io_detail::default_line_source_limits() = saved;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  read_frames(reinterpret_cast<const char*>(data), size);
  compare_line_splitting(data, size);
  return 0;
}
