// The replay backend: plays a *.landmarks.jsonl recording as if it were an estimator.
// Each estimate() returns the recording's next frame (its own time stamp is kept; args.t is
// ignored) and reports the end of the recording as an error status "end of recording".
// Parts not asked for in estimate_args are removed from the returned frame.
//
// Several people (max_people > 1): the lines of one time stamp are one frame's people (a
// version-2 recording: one line per person in view and frame, docs/file-formats.md);
// last_people() gives them (the first max_people, in the file's order) and estimate() the first.
// A version-1 recording then plays as one person, id 0.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap {

class replay_estimator final : public estimator {
 public:
  /// Opens the recording; the error names the file and line of a broken header.
  static status open(const std::string& path, std::unique_ptr<replay_estimator>& out,
                     int max_people = 1);

  status estimate(const estimate_args& args, landmark_frame& out) override;
  people_view last_people() const override;
  std::string_view name() const override { return "replay"; }
  const landmark_file_header& header() const { return reader_.header(); }
  /// True once estimate() has reported the end of the recording.
  bool finished() const { return finished_; }

 private:
  replay_estimator() = default;
  landmark_reader reader_;
  bool finished_ = false;
  int max_people_ = 1;
  // Several people: the frame's people, and the line read past them (the next frame's first).
  std::array<landmark_frame, k_max_people> people_;
  int people_count_ = 0;
  landmark_frame ahead_;
  bool has_ahead_ = false;
};

}  // namespace avatarmap
