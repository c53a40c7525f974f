#include "model_cache.hpp"

#include <fcntl.h>
#include <onnxruntime_session_options_config_keys.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <thread>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#define AVATARMAP_CPUID 1
#elif defined(__linux__)
#include <sys/auxv.h>
#endif

namespace avatarmap {

namespace fs = std::filesystem;

namespace {

// Bump when what is saved, or how it is loaded, changes: old copies then go unused.
constexpr const char* k_cache_format = "avatarmap ort-optimized 1";
constexpr const char* k_cache_folder = "ort-optimized";
// Initializers of at least this many bytes go to the data file, which ORT maps at load
// (offsets 64-byte aligned, so the kernels read the weights as fast as from the heap);
// smaller ones stay in the graph.
constexpr const char* k_external_min_bytes = "1024";
// A data file no .onnx refers to any more (a lost race, a copy made again) is removed by the
// next writer of the same model once it is this old: a writer still between saving its data
// and renaming its .onnx is younger by far.
constexpr auto k_orphan_age = std::chrono::minutes(1);

uint64_t fnv1a(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

void append_hex(std::string& out, uint64_t v, int digits) {
  static const char* k = "0123456789abcdef";
  for (int i = digits - 1; i >= 0; --i) out += k[(v >> (4 * i)) & 15];
}

// The instruction-set features ORT's kernels are chosen by (MLAS picks SSE/AVX/AVX2/AVX-512
// code paths and the NCHWc block size from them): the vendor, CPUID leaves 1 (not EBX: it
// holds the core's APIC id) and 7, and the register state the OS enables (XCR0).
std::string cpu_features() {
  std::string out;
#ifdef AVATARMAP_CPUID
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (!__get_cpuid(0, &a, &b, &c, &d)) return "x86 no cpuid";
  const unsigned max_leaf = a;
  for (unsigned v : {b, d, c}) append_hex(out, v, 8);
  unsigned c1 = 0;
  if (__get_cpuid(1, &a, &b, &c, &d)) {
    c1 = c;
    for (unsigned v : {c, d}) append_hex(out, v, 8);
  }
  if (max_leaf >= 7) {
    __cpuid_count(7, 0, a, b, c, d);
    for (unsigned v : {b, c, d}) append_hex(out, v, 8);
    __cpuid_count(7, 1, a, b, c, d);
    append_hex(out, a, 8);
  }
  if (c1 & bit_OSXSAVE) {
    unsigned lo = 0, hi = 0;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    append_hex(out, (static_cast<uint64_t>(hi) << 32) | lo, 16);
  }
#elif defined(__linux__) && defined(AT_HWCAP)
  append_hex(out, getauxval(AT_HWCAP), 16);
#ifdef AT_HWCAP2
  append_hex(out, getauxval(AT_HWCAP2), 16);
#endif
#else
  out = "unknown";
#endif
  return out;
}

// What every key shares: the format, the runtime and the CPU (computed once).
const std::string& key_prefix() {
  static const std::string prefix = std::string(k_cache_format) + "\nonnxruntime " +
                                    Ort::GetVersionString() + "\ncpu " + cpu_features() + "\n";
  return prefix;
}

#if defined(__APPLE__)
int64_t ns(const struct timespec& t) { return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec; }
int64_t mtime_ns(const struct stat& st) { return ns(st.st_mtimespec); }
int64_t ctime_ns(const struct stat& st) { return ns(st.st_ctimespec); }
#else
int64_t ns(const struct timespec& t) { return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec; }
int64_t mtime_ns(const struct stat& st) { return ns(st.st_mtim); }
int64_t ctime_ns(const struct stat& st) { return ns(st.st_ctim); }
#endif

// A name part no other writer (process or thread) uses at the same time.
std::string unique_suffix() {
  static std::atomic<unsigned> counter{0};
  const auto t = std::chrono::steady_clock::now().time_since_epoch().count();
  std::string s = std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-";
  append_hex(s, static_cast<uint64_t>(t) & 0xffffffull, 6);
  return s;
}

void note_unwritable(const std::string& dir, const std::string& why) {
  static std::once_flag once;
  std::call_once(once, [&] {
    std::fprintf(stderr,
                 "avatarmap: note: cannot write the optimised-model cache %s (%s); the models "
                 "are optimised at every start instead (AVATARMAP_ORT_CACHE=DIR puts the cache "
                 "elsewhere, =off turns it off)\n",
                 dir.c_str(), why.c_str());
  });
}

// Creates `path` (which must not exist) and closes it: tells whether the folder takes new
// files before ORT is asked to write there. errno on failure.
bool create_empty(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

// Removes data files of `prefix` other than `keep`, and temporary graphs of `prefix`, once they
// are old enough that no writer can still be about to use them.
void remove_orphans(const fs::path& dir, const std::string& prefix, const std::string& keep) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0 || name == keep) continue;
    const bool data = name.size() > 5 && name.compare(name.size() - 5, 5, ".data") == 0;
    const bool tmp = name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0;
    if (!data && !tmp) continue;
    std::error_code e2;
    const auto t = fs::last_write_time(it->path(), e2);
    if (!e2 && now - t > k_orphan_age) fs::remove(it->path(), e2);
  }
}

}  // namespace

std::string model_cache_dir(const std::string& model_path) {
  if (const char* e = std::getenv("AVATARMAP_ORT_CACHE"); e && *e) {
    const std::string v = e;
    if (v == "off" || v == "0") return {};
    return v;
  }
  return (fs::path(model_path).parent_path() / k_cache_folder).string();
}

std::string model_cache_key(const std::string& model_path) {
  struct stat st;
  if (::stat(model_path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return {};
  std::string k = key_prefix();
  k += "size " + std::to_string(static_cast<long long>(st.st_size)) + " mtime " +
       std::to_string(mtime_ns(st)) + " ctime " + std::to_string(ctime_ns(st)) + " inode " +
       std::to_string(static_cast<unsigned long long>(st.st_ino)) + " device " +
       std::to_string(static_cast<unsigned long long>(st.st_dev));
  std::string out;
  append_hex(out, fnv1a(k), 16);
  return out;
}

const char* model_cache_use_name(model_cache_use u) {
  switch (u) {
    case model_cache_use::hit:
      return "hit";
    case model_cache_use::made:
      return "made";
    case model_cache_use::remade:
      return "remade";
    case model_cache_use::unwritable:
      return "unwritable";
    default:
      return "off";
  }
}

cached_session open_cached_session(Ort::Env& env, const std::string& model_path,
                                   const Ort::SessionOptions& so, const std::string& cache_dir) {
  cached_session out;
  const std::string key = cache_dir.empty() ? std::string() : model_cache_key(model_path);
  if (key.empty()) {
    out.session = std::make_unique<Ort::Session>(env, model_path.c_str(), so);
    return out;
  }
  const fs::path dir(cache_dir);
  const std::string prefix = fs::path(model_path).stem().string() + "." + key + ".";
  const fs::path cached = dir / (prefix + "onnx");
  std::error_code ec;
  const bool had_copy = fs::exists(cached, ec);
  if (had_copy) {
    try {
      // Every optimiser ran before the graph was saved; running them again finds nothing.
      Ort::SessionOptions lo = so.Clone();
      lo.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_DISABLE_ALL);
      out.session = std::make_unique<Ort::Session>(env, cached.c_str(), lo);
      out.use = model_cache_use::hit;
      out.cache_path = cached.string();
      return out;
    } catch (const Ort::Exception&) {
      // Truncated, corrupt or its data file gone: made again below, the rename replaces it.
    }
  }

  const std::string unique = unique_suffix();
  const std::string data_name = prefix + unique + ".data";
  const fs::path tmp = dir / (prefix + unique + ".onnx.tmp");
  std::string why;
  fs::create_directories(dir, ec);
  if (ec)
    why = ec.message();
  else if (!create_empty(tmp))
    why = std::strerror(errno);
  auto source_only = [&](const std::string& reason) {
    std::error_code e2;
    fs::remove(tmp, e2);
    fs::remove(dir / data_name, e2);
    out.session = std::make_unique<Ort::Session>(env, model_path.c_str(), so);
    note_unwritable(cache_dir, reason);
    out.use = model_cache_use::unwritable;
  };
  if (!why.empty()) {
    source_only(why);
    return out;
  }
  Ort::SessionOptions mo = so.Clone();
  mo.SetOptimizedModelFilePath(tmp.c_str());
  mo.AddConfigEntry(kOrtSessionOptionsOptimizedModelExternalInitializersFileName,
                    data_name.c_str());
  mo.AddConfigEntry(kOrtSessionOptionsOptimizedModelExternalInitializersMinSizeInBytes,
                    k_external_min_bytes);
  // ORT warns that a graph saved after the layout transforms only suits this CPU: the key
  // holds the CPU's features, so another CPU never loads it.
  mo.SetLogSeverityLevel(ORT_LOGGING_LEVEL_ERROR);
  try {
    out.session = std::make_unique<Ort::Session>(env, model_path.c_str(), mo);
  } catch (const Ort::Exception& ex) {
    // A bad source model throws again here (the caller sees ORT's own message); a failed
    // save leaves the source model in use.
    source_only(ex.what());
    return out;
  }
  fs::rename(tmp, cached, ec);
  if (ec) {
    std::error_code e2;
    fs::remove(tmp, e2);
    fs::remove(dir / data_name, e2);
    note_unwritable(cache_dir, ec.message());
    out.use = model_cache_use::unwritable;
    return out;
  }
  remove_orphans(dir, prefix, data_name);
  out.use = had_copy ? model_cache_use::remade : model_cache_use::made;
  out.cache_path = cached.string();
  return out;
}

std::string load_in_parallel(const std::function<std::string()>& first,
                             const std::function<std::string()>& second) {
  std::string second_message;
  std::exception_ptr second_error;
  auto run_second = [&] {
    try {
      second_message = second();
    } catch (...) {
      second_error = std::current_exception();
    }
  };
  std::thread worker;
  try {
    worker = std::thread(run_second);
  } catch (const std::system_error&) {
    run_second();
  }
  std::string first_message;
  std::exception_ptr first_error;
  try {
    first_message = first();
  } catch (...) {
    first_error = std::current_exception();
  }
  if (worker.joinable()) worker.join();
  if (first_error) std::rethrow_exception(first_error);
  if (!first_message.empty()) return first_message;
  if (second_error) std::rethrow_exception(second_error);
  return second_message;
}

std::string with_model_name(const std::string& path, const std::function<std::string()>& load) {
  try {
    return load();
  } catch (const Ort::Exception& ex) {
    return path + ": ONNX Runtime: " + ex.what();
  }
}

}  // namespace avatarmap
