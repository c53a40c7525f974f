// Streaming reader and writer of *.pose.jsonl (docs/file-formats.md).
// Quaternions are written [x, y, z, w]; bones are VRM 1.0 names; bones at identity may be
// omitted when reading (missing bones mean identity). "foot_contact": [left, right] is always
// written and optional when reading (older files: 0, 0; values clamped to [0, 1]).
// "blendshapes": {ARKit name: weight} is written (all 52) when any weight is non-zero and
// optional when reading (missing shapes are 0). Same error and atomicity rules as
// landmark_file.hpp.
#pragma once

#include <memory>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

struct pose_file_header {
  bool present = false;
  int version = 1;
  double fps = 0.0;  // 0 = not given (irregular times)
};

class pose_reader {
 public:
  pose_reader();
  ~pose_reader();
  pose_reader(const pose_reader&) = delete;
  pose_reader& operator=(const pose_reader&) = delete;

  /// Opens `path` ("-" = standard input) and reads the header line if there is one. Fails
  /// when the file cannot be opened (status_code::io) or the header is bad
  /// (status_code::parse).
  status open(const std::string& path);
  status open_memory(const char* data, std::size_t size, const std::string& name = "<memory>");
  const pose_file_header& header() const;
  /// Reads the next pose (reset to rest first). Unknown bone, expression or blendshape names
  /// are an error naming them; a non-finite weight is an error; quaternions are normalised; a zero
  /// or non-finite quaternion is an error.
  read_result next(proxy_pose& out);
  const std::string& error() const;
  /// The kind of the last error: parse (a malformed or over-long line), io (reading failed).
  status_code error_code() const;
  long line() const;

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

struct pose_write_options {
  bool write_confidence = false;  // adds "confidence": {bone: c} per frame
  bool skip_identity = false;     // omit bones whose rotation is exactly identity
};

class pose_writer {
 public:
  pose_writer();
  ~pose_writer();
  pose_writer(const pose_writer&) = delete;
  pose_writer& operator=(const pose_writer&) = delete;

  /// Like landmark_writer::open: atomic via a temporary file, "-" = standard output. Writes
  /// the header {"format":"avatarmap.pose","version":1(,"fps":F when fps > 0)}.
  status open(const std::string& path, const pose_file_header& header,
              const pose_write_options& options = {});
  /// Writes one pose: t, hips_position, all bones (VRM 1.0 names, bone enum order,
  /// [x, y, z, w]), all expressions, all 52 blendshapes when any is non-zero (none when all
  /// are 0), and confidence when asked. Non-finite numbers are
  /// written as null (which the reader rejects).
  status write(const proxy_pose& pose);
  status commit();

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
