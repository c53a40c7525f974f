// The start-up cache of ONNX Runtime-optimised models (internal to src/capture/onnx; issue 11).
//
// Creating a session from a converted .onnx model spends most of its time parsing the
// protobuf, copying the weights and running the graph optimisers (fusions, NCHWc layout).
// The first session of a model saves the graph ORT optimised (ORT_ENABLE_ALL) as an .onnx
// whose weights sit in a separate data file; later sessions load that with the optimisers
// off, and ORT maps the data file instead of parsing and copying it. Outputs are bitwise
// the same as from the source model (tests/capture/onnx/model_cache_test.cpp).
//
// Layout: <cache dir>/<stem>.<key>.onnx refers to its own <stem>.<key>.<unique>.data. The
// key (16 hex digits) hashes what makes a saved graph valid: this cache's format, the ONNX
// Runtime version, the CPU's features (the layout transforms pick kernels for the CPU the
// graph was optimised on) and the source file's identity (size, modification and change
// times, inode, device). A new model, runtime or CPU gets a new name, never the old file.
#pragma once

#include <onnxruntime_cxx_api.h>

#include <functional>
#include <memory>
#include <string>

namespace avatarmap {

/// The folder for the optimised copies of `model_path`: $AVATARMAP_ORT_CACHE when set ("off"
/// or "0": "" = no cache), else "ort-optimized" next to the model.
std::string model_cache_dir(const std::string& model_path);

/// The key of `model_path`'s optimised copy (16 lower-case hex digits); "" when the file
/// cannot be stat'ed.
std::string model_cache_key(const std::string& model_path);

/// Where a session's graph came from.
enum class model_cache_use {
  off,         // no cache folder: the source model, optimised at load
  hit,         // the optimised copy, loaded with the optimisers off
  made,        // the source model; its optimised copy was written for next time
  remade,      // the copy could not be loaded (truncated, corrupt): made again
  unwritable,  // the folder cannot be written: the source model (noted once on stderr)
};

/// A short word for `u` ("off", "hit", "made", "remade", "unwritable").
const char* model_cache_use_name(model_cache_use u);

struct cached_session {
  std::unique_ptr<Ort::Session> session;
  model_cache_use use = model_cache_use::off;
  std::string cache_path;  // the optimised .onnx loaded or written; "" when none
};

/// Creates a session for the .onnx at `model_path` with `so` (full graph optimisation),
/// through the optimised copy in `cache_dir` ("" = no cache): loads the copy when there is
/// one (optimisers off), else creates the session from the source and saves its optimised
/// graph (temporary name, then an atomic rename; the data file is never replaced). A copy
/// ORT refuses is made again; a folder that cannot be created or written leaves the source
/// model in use and prints one note per process. Throws Ort::Exception for the source model
/// as Ort::Session does.
cached_session open_cached_session(Ort::Env& env, const std::string& model_path,
                                   const Ort::SessionOptions& so, const std::string& cache_dir);

/// Runs `first` on this thread and `second` on another at the same time (a pipeline's two
/// sessions are created side by side: most of the work is single-threaded) and waits for
/// both. Returns first's message when it is not empty, else second's. An exception from
/// either is rethrown here after both have finished, first's before second's. Without a
/// second thread (the system refuses one) they run one after the other.
std::string load_in_parallel(const std::function<std::string()>& first,
                             const std::function<std::string()>& second);

/// Runs `load` and turns an ONNX Runtime exception from it into a message naming `path` (so
/// that a session created on another thread by load_in_parallel still names its model).
std::string with_model_name(const std::string& path, const std::function<std::string()>& load);

}  // namespace avatarmap
