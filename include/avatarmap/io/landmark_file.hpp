// Streaming reader and writer of *.landmarks.jsonl (docs/file-formats.md).
// Constant memory on any file size: one line is held at a time. Errors name the file and
// line. Writes are atomic: a temporary file beside the target is renamed over it by
// commit(); a writer destroyed without commit() leaves any existing target untouched.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// The optional first line {"format":"avatarmap.landmarks","version":1,...}. Version 2 (several
/// people): each line also carries "person" and must carry "t" (docs/file-formats.md).
struct landmark_file_header {
  bool present = false;  // false when the file has no header line
  int version = 1;       // 1 or 2; the writer writes this one
  int image_width = 0;   // 0 = not given
  int image_height = 0;
  double fps = 0.0;  // 0 = not given
};

enum class read_result { frame, end, error };

class landmark_reader {
 public:
  landmark_reader();
  ~landmark_reader();
  landmark_reader(const landmark_reader&) = delete;
  landmark_reader& operator=(const landmark_reader&) = delete;

  /// Opens `path` ("-" = standard input) and reads the header line if there is one. Fails
  /// when the file cannot be opened (status_code::io) or the header is bad (wrong format,
  /// version > 2: status_code::parse).
  status open(const std::string& path);
  /// Reads from a memory buffer (not copied: it must outlive the reader). For tests/fuzzing.
  status open_memory(const char* data, std::size_t size, const std::string& name = "<memory>");

  const landmark_file_header& header() const;

  /// Reads the next frame into `out` (all parts cleared first). On error, error() says what
  /// and where ("FILE:LINE: ..."); the reader stays usable: the next call goes on with the
  /// following line, so a caller may skip bad lines. Blank lines are skipped.
  read_result next(landmark_frame& out);
  const std::string& error() const;
  /// The kind of the last error: parse (a malformed or over-long line), io (reading failed).
  status_code error_code() const;
  /// 1-based number of the line last read.
  long line() const;
  /// Only this person's lines from now on (-1, the default: every line). next() passes the
  /// others over; a version-1 file's lines are all person 0.
  void set_person(int person);

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

/// The person ids of a landmark file, ascending (one pass over it; {0} for a version-1 file).
/// Fails as landmark_reader::open does, or on the first malformed line.
status people_in_file(const std::string& path, std::vector<int>& ids);

class landmark_writer {
 public:
  landmark_writer();
  ~landmark_writer();
  landmark_writer(const landmark_writer&) = delete;
  landmark_writer& operator=(const landmark_writer&) = delete;

  /// Starts writing to a temporary file `path.tmp.XXXXXX` beside `path` ("-" = standard
  /// output, not atomic) and writes the header line (always; `header.present` is ignored;
  /// image_size when both sizes are > 0, fps when > 0). Fails when the temporary file
  /// cannot be created (message names `path`).
  status open(const std::string& path, const landmark_file_header& header);
  /// Writes one frame (only the parts it has; with a version-2 header also its person).
  /// Numbers are the shortest text that reads back bit-identical; non-finite numbers are
  /// written as null. Fails on a write error.
  status write(const landmark_frame& frame);
  /// Flushes, fsyncs and renames the temporary file over `path`. Destroying the writer
  /// without commit() removes the temporary file and leaves `path` untouched.
  status commit();

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
