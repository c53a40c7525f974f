// Helpers shared by the libFuzzer targets: invariant checks that abort (libFuzzer then saves
// the input) and a private scratch folder for the readers that take a path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace avatarmap::fuzz {

/// Aborts with "invariant failed: `what`" when `ok` is false.
void check(bool ok, const char* what);

/// A folder made for this process (mkdtemp: $TMPDIR/avatarmap-fuzz-PID-XXXXXX, /tmp without
/// TMPDIR), removed at exit, or by the next fuzz process when a crash ended this one. Readers
/// resolve relative URIs against the input's folder, so inputs are written here, away from
/// any real file.
const std::string& scratch_dir();

/// Writes `size` bytes to scratch_dir()/`name` (replaced) and returns the path. Aborts when
/// the file cannot be written (the harness, not the reader, failed).
std::string write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size);

/// Number of entries in scratch_dir() (to check that a failed writer leaves no file behind).
int scratch_entries();

/// Removes every entry of scratch_dir() (not the folder).
void clear_scratch();

}  // namespace avatarmap::fuzz
