// What `avatarmap view` and `avatarmap live --serve` share about the viewer's server
// (stream/pose_server.hpp, docs/viewer.md): where the page and the modules are, how a
// [HOST:]PORT option reads, the built-in avatar, the server's event lines and its exposure
// warning on standard error.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/stream/pose_server.hpp"

namespace avatarmap::cli {

/// Options with the page and modules folders (find_resource(): $AVATARMAP_VIEWER_PAGE /
/// $AVATARMAP_VIEWER_MODULES, else the installed ones, else the source tree's viewer/ and the
/// cache that scripts/fetch_viewer_modules.sh fills), event lines printed as "COMMAND: LINE" and
/// `port_option` (the option that sets the port: "--port", "--serve") for the port-in-use
/// message.
pose_server_options default_viewer_options(const char* command, const char* port_option);

/// Parses "PORT" or "HOST:PORT" ("[V6]:PORT") into out_host (unchanged when absent) and
/// out_port (0..65535); false with a message otherwise.
bool parse_host_port(const std::string& text, std::string& out_host, int& out_port,
                     std::string& error);

/// Makes the server show the built-in avatar (`avatarmap avatar`): its bytes in
/// options.avatar_data, served from memory as /avatar.vrm and named "built-in avatar" on the page
/// (no file is written). Fails only when the avatar cannot be made (out of memory).
status use_builtin_avatar(pose_server_options& options);

/// When `server` listens beyond loopback (pose_server::exposed()): two lines on standard error,
/// "COMMAND: listening on ADDRESS ...: other machines reach it at URL, ..." and a warning that
/// the page, the avatar and the poses are readable by anyone on the network who can reach the
/// port. Nothing otherwise.
void print_exposure(const char* command, const pose_server& server);

}  // namespace avatarmap::cli
