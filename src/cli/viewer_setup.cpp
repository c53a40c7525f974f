// src/cli/viewer_setup.hpp.
#include "cli/viewer_setup.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/io/resources.hpp"

namespace avatarmap::cli {

namespace {

// A folder no rule found is still named (the last candidate looked at: the source tree's, which
// scripts/fetch_viewer_modules.sh fills), so that the server's message says where it looked.
std::string folder_or_first_tried(resource kind) {
  resource_lookup r = find_resource(kind);
  if (!r.folder.empty() || r.tried.empty()) return r.folder;
  const std::string& last = r.tried.back();
  return last.substr(0, last.rfind(" ("));
}

}  // namespace

pose_server_options default_viewer_options(const char* command, const char* port_option) {
  pose_server_options o;
  o.page_dir = folder_or_first_tried(resource::viewer_page);
  o.modules_dir = folder_or_first_tried(resource::viewer_modules);
  o.port_option = port_option;
  std::string prefix = std::string(command) + ": ";
  o.on_event = [prefix](std::string_view line) {
    std::fprintf(stderr, "%s%.*s\n", prefix.c_str(), static_cast<int>(line.size()), line.data());
  };
  return o;
}

bool parse_host_port(const std::string& text, std::string& out_host, int& out_port,
                     std::string& error) {
  std::string host = out_host, port = text;
  if (const auto colon = text.rfind(':'); colon != std::string::npos) {
    host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
      host = host.substr(1, host.size() - 2);
  }
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (port.empty() || *end != '\0' || p < 0 || p > 65535 || host.empty()) {
    error = "'" + text + "' is not PORT or HOST:PORT with a port in 0..65535";
    return false;
  }
  out_host = host;
  out_port = static_cast<int>(p);
  return true;
}

status use_builtin_avatar(pose_server_options& options) {
  std::string glb;
  if (status st = builtin_avatar_glb(builtin_avatar_options{}, glb); !st) return st;
  options.avatar_path.clear();
  options.avatar_data = std::move(glb);
  options.avatar_name = "built-in avatar";
  return {};
}

void print_exposure(const char* command, const pose_server& server) {
  if (!server.exposed()) return;
  const std::string address = server.listen_address();
  const char* every = address.rfind("0.0.0.0:", 0) == 0 ? " (every IPv4 address of this machine)"
                      : address.rfind("[::]:", 0) == 0  ? " (every address of this machine)"
                                                        : "";
  const std::vector<std::string> urls = server.network_urls();
  std::string reach;
  for (std::size_t i = 0; i < urls.size() && i < 4; ++i) reach += (i ? ", " : "") + urls[i];
  if (urls.size() > 4) reach += ", ...";
  if (reach.empty()) reach = "this machine's addresses (none found besides loopback)";
  std::fprintf(stderr, "%s: listening on %s%s: other machines reach it at %s\n", command,
               address.c_str(), every, reach.c_str());
  std::fprintf(stderr,
               "%s: warning: the page, the avatar and the poses are readable, unencrypted, by "
               "anyone on the network who can reach port %d; listen on 127.0.0.1 (the default) "
               "to keep them on this machine\n",
               command, server.port());
}

}  // namespace avatarmap::cli
