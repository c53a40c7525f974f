// The replay backend: plays a *.landmarks.jsonl recording as if it were an estimator.
// Each estimate() returns the recording's next frame (its own time stamp is kept; args.t is
// ignored) and reports the end of the recording as an error status "end of recording".
// Parts not asked for in estimate_args are removed from the returned frame.
#pragma once

#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap {

class replay_estimator final : public estimator {
 public:
  /// Opens the recording; the error names the file and line of a broken header.
  static status open(const std::string& path, std::unique_ptr<replay_estimator>& out);

  status estimate(const estimate_args& args, landmark_frame& out) override;
  std::string_view name() const override { return "replay"; }
  const landmark_file_header& header() const { return reader_.header(); }
  /// True once estimate() has reported the end of the recording.
  bool finished() const { return finished_; }

 private:
  replay_estimator() = default;
  landmark_reader reader_;
  bool finished_ = false;
};

}  // namespace avatarmap
