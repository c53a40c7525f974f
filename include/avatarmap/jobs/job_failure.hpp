// Why a file workflow (avatarmap/jobs/*) failed, beside its status message: the C API turns it
// into a status code and the CLI into an exit status or a hint, without reading the message.
#pragma once

#include <cstdint>

namespace avatarmap {

enum class job_failure : std::uint8_t {
  none,
  invalid_argument,  // a field of the job (options, frame rate, output name, an empty clip)
  input_io,          // an input file (landmarks, avatar, mapping table) cannot be read
  input_parse,       // an input file is malformed (a landmark line, an avatar, a table)
  output_io,         // the output cannot be written (or the sink refused a pose)
  internal,          // a stage of the library failed on valid input (the estimator on a frame)
};

}  // namespace avatarmap
