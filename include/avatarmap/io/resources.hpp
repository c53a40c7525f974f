// Where the project's shipped folders are found: the mapping tables, the capture models and
// the browser viewer's page and modules. One lookup order for every caller (the CLI, the C API
// and through it Python), written down in docs/architecture.md ("Resources"):
//
//   1. the explicit argument (--models DIR, avm_set_mappings_folder(), a Python argument);
//   2. the environment ($AVATARMAP_MAPPINGS, $AVATARMAP_MODELS + "/onnx",
//      $AVATARMAP_VIEWER_PAGE, $AVATARMAP_VIEWER_MODULES);
//   3. the installed location, found from where the running code lies (the executable, or the
//      shared library that holds this code) as `cmake --install` lays it out:
//      BINDIR/../share/avatarmap/NAME or LIBDIR/../share/avatarmap/NAME (GNUInstallDirs'
//      directories, relative, so a tree installed with any --prefix or moved finds its own);
//   4. the source tree this library was built from (mappings/, .cache/avatarmap/models/onnx,
//      viewer/, .cache/avatarmap/viewer).
//
// Rules 1 and 2 are taken as given (a folder that does not exist then fails with a message
// that names it: the user asked for it); rules 3 and 4 are taken only when the folder exists.
// An installed tool therefore uses its installed tables even when the source tree it was built
// from is still there (and possibly newer or older), and a build run in place, which has no
// installed tree beside it, uses its source tree.
#pragma once

#include <string>
#include <vector>

namespace avatarmap {

/// The shipped folders.
enum class resource {
  mappings,        ///< the mapping tables (mappings/)
  models,          ///< the converted ONNX models (the onnx/ folder of the models cache)
  viewer_page,     ///< the browser viewer's page (viewer/)
  viewer_modules,  ///< three.js and three-vrm (scripts/fetch_viewer_modules.sh)
};

/// What find_resource() found and how.
struct resource_lookup {
  /// The folder to use; empty when no rule found one.
  std::string folder;
  /// The rule that found it: "argument", "environment AVATARMAP_MAPPINGS" (the variable's
  /// name), "installed" or "source tree"; empty when none did.
  std::string source;
  /// Every candidate looked at, in order, each as "FOLDER (RULE)" with ": not a folder" for
  /// the installed and source-tree candidates that do not exist. Filled whether or not one was
  /// found (what `avatarmap backends` prints and what an error message lists).
  std::vector<std::string> tried;
};

/// The resource's name as `avatarmap backends` prints it ("mappings", "models", "viewer page",
/// "viewer modules").
const char* resource_name(resource kind);

/// The environment variable of rule 2 ("AVATARMAP_MAPPINGS", "AVATARMAP_MODELS",
/// "AVATARMAP_VIEWER_PAGE", "AVATARMAP_VIEWER_MODULES"). For models the folder is the
/// variable's value + "/onnx" (the variable names the models cache, as the scripts use it).
const char* resource_environment(resource kind);

/// Looks for `kind` in the order above; `explicit_folder` is rule 1 (empty: none given).
/// Reads the environment and the file system on each call (nothing cached); thread-safe as
/// long as no other thread changes the environment. Never throws except std::bad_alloc.
resource_lookup find_resource(resource kind, const std::string& explicit_folder = {});

/// How a message should write a command of this program so that it runs when copied into a
/// shell: "avatarmap" when the first `avatarmap` on $PATH is the running executable (the same
/// file), else the running executable's absolute path (a build folder, an install whose bin/ is
/// not on the PATH), else "avatarmap" when that path is unknown. For the CLI's messages (the C
/// API's code runs in another program: it gives that program's path).
std::string program_command();

/// How a message should name the project script `relative` ("scripts/prepare_capture.sh") so
/// that it runs from any folder: its absolute path in the source tree this was built from
/// when it is there, else `relative` followed by " (in a checkout of avatarmap)".
std::string script_command(const std::string& relative);

}  // namespace avatarmap
