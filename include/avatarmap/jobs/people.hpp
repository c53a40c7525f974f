// Several people in one landmark file (docs/file-formats.md, "Version 2: several people"):
// which of them a solve or convert run takes and where each one's output goes, decided once
// for the CLI, the C API and Python. A file of one person (every version-1 file) keeps its
// output name; a file of several writes one output per person, its id before the extension
// (take.glb -> take.p0.glb, take.p3.glb; take.pose.jsonl -> take.p0.pose.jsonl), unless one
// person is asked for.
#pragma once

#include <string>
#include <vector>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// Person ids as messages list them: "0, 3, 7".
std::string person_id_list(const std::vector<int>& ids);

/// One person to solve and the output it goes to.
struct person_run {
  int person = 0;
  std::string output;
};

/// `output` with ".p<person>" before its extension (the known two-part ones .pose.jsonl and
/// .landmarks.jsonl kept whole); without an extension, appended.
std::string person_output_path(const std::string& output, int person);

/// The runs for `input` with `person` (-1: every person in the file) and `output`. A regular
/// file is scanned for its ids when it is version 2 (landmark_file.hpp people_in_file); a
/// version-1 file is person 0 alone. Fails (invalid_argument) when `person` is not in the
/// file (the message lists its ids), or when several people would share standard output
/// ("-"); standard input (read once) cannot be scanned: a version-2 stream needs `person`
/// (the solve job says so). The input's own errors keep their codes (io, parse).
status plan_person_runs(const std::string& input, int person, const std::string& output,
                        std::vector<person_run>& out);

}  // namespace avatarmap
