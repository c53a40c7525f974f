// What an input text names for video_source::open(): a file or folder, a printf pattern of
// image files, an FFmpeg input device ("FORMAT:DEVICE") or a URL ("SCHEME://..."). Internal
// to src/capture. Pure: the caller says whether the text names an existing path, so that the
// rules have known answers in tests (tests/media/input_spec_test.cpp).
#pragma once

#include <cstdint>
#include <string>

namespace avatarmap {

enum class input_kind : std::uint8_t {
  path,     // a file or a folder (which one, or neither, is for open() to find out)
  pattern,  // not an existing path, and has a '%': a printf pattern (checked by open())
  device,   // FORMAT:DEVICE, FORMAT an FFmpeg input device name ("v4l2", "lavfi", ...)
  url,      // SCHEME://REST
};

struct input_spec {
  input_kind kind = input_kind::path;
  /// device: the format ("v4l2"); url: the scheme in lower case ("udp"); otherwise "".
  std::string name;
  /// path, pattern: the path ("file:" removed); device: what follows "FORMAT:" (may be
  /// empty); url: the URL, its scheme in lower case (FFmpeg matches schemes by case).
  std::string target;
};

/// Classifies `text`, in this order:
///  1. `exists` (it names an existing file or folder): that path, whatever it contains;
///  2. "file:PATH": the path PATH (FFmpeg's spelling of a local file);
///  3. SCHEME "://" REST, SCHEME a letter then letters, digits, '+', '-' or '.': a URL;
///  4. NAME ":" REST, NAME two or more letters, digits or '_' (so never a drive letter
///     "C:"): a device;
///  5. a '%' anywhere: a pattern;
///  6. otherwise a path (a missing one: open() says so).
input_spec classify_input(const std::string& text, bool exists);

// shown_input(): avatarmap/media/video_source.hpp (public: the capture job uses it).

}  // namespace avatarmap
