// Several people in one landmark file: the runs and their outputs. See jobs/people.hpp.
#include "avatarmap/jobs/people.hpp"

#include <filesystem>

#include "avatarmap/io/landmark_file.hpp"

namespace avatarmap {

std::string person_id_list(const std::vector<int>& ids) {
  std::string s;
  for (std::size_t i = 0; i < ids.size(); ++i) s += (i == 0 ? "" : ", ") + std::to_string(ids[i]);
  return s;
}

std::string person_output_path(const std::string& output, int person) {
  const std::string tag = ".p" + std::to_string(person);
  const std::size_t slash = output.find_last_of('/');
  const std::size_t name = slash == std::string::npos ? 0 : slash + 1;
  for (const char* two : {".pose.jsonl", ".landmarks.jsonl"}) {
    const std::string ext(two);
    if (output.size() > name + ext.size() &&
        output.compare(output.size() - ext.size(), ext.size(), ext) == 0)
      return output.substr(0, output.size() - ext.size()) + tag + ext;
  }
  const std::size_t dot = output.find_last_of('.');
  if (dot == std::string::npos || dot <= name) return output + tag;
  return output.substr(0, dot) + tag + output.substr(dot);
}

status plan_person_runs(const std::string& input, int person, const std::string& output,
                        std::vector<person_run>& out) {
  out.clear();
  std::error_code ec;
  const bool regular = input != "-" && std::filesystem::is_regular_file(input, ec);
  std::vector<int> ids;
  if (regular) {
    // A version-1 file is one person; only a version-2 file is scanned.
    landmark_reader reader;
    if (status st = reader.open(input); !st.ok()) return st;
    if (reader.header().version >= 2) {
      if (status st = people_in_file(input, ids); !st.ok()) return st;
    } else {
      ids = {0};
    }
  }
  if (person >= 0) {
    bool found = !regular;  // a stream is taken at its word
    for (int id : ids) found = found || id == person;
    if (!found)
      return status::invalid_argument(
          input + ": no person " + std::to_string(person) +
          " (its people: " + (ids.empty() ? "none" : person_id_list(ids)) + ")");
    out.push_back({person, output});
    return {};
  }
  if (ids.size() <= 1) {
    out.push_back({ids.empty() ? -1 : ids[0], output});
    return {};
  }
  if (output == "-")
    return status::invalid_argument(input + " has " + std::to_string(ids.size()) + " people (" +
                                    person_id_list(ids) +
                                    "): they cannot share standard output; give an output file "
                                    "(one per person is written) or one person");
  for (int id : ids) out.push_back({id, person_output_path(output, id)});
  return {};
}

}  // namespace avatarmap
