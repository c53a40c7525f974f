// What `avatarmap view` and `avatarmap live --serve` share about the viewer's server
// (stream/pose_server.hpp, docs/viewer.md): where the page and the modules are, how a
// [HOST:]PORT option reads, and the server's event lines on standard error.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/stream/pose_server.hpp"

namespace avatarmap::cli {

/// Options with the page folder (AVATARMAP_VIEWER_PAGE, else the source tree's viewer/, else
/// the installed one), the modules folder (AVATARMAP_VIEWER_MODULES, else the cache that
/// scripts/fetch_viewer_modules.sh fills) and event lines printed as "COMMAND: LINE".
pose_server_options default_viewer_options(const char* command);

/// Parses "PORT" or "HOST:PORT" ("[V6]:PORT") into out_host (unchanged when absent) and
/// out_port (0..65535); false with a message otherwise.
bool parse_host_port(const std::string& text, std::string& out_host, int& out_port,
                     std::string& error);

/// The built-in avatar (`avatarmap avatar`) written to a temporary file for the viewer to serve,
/// removed when this goes out of scope.
struct builtin_avatar_file {
  std::string path;  // empty until write() succeeds
  status write();
  ~builtin_avatar_file();
};

}  // namespace avatarmap::cli
