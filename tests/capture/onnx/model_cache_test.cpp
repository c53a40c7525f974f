// Tests of capture/onnx/model_cache.hpp, the start-up cache of ORT-optimised models: the copy
// is made on the first load and used on the second, a truncated or corrupt copy is made again,
// a folder that cannot be written leaves the source model in use, a replaced model gets a new
// key, and every way gives the same bytes out as the source model loaded without the cache.
//
// Models: $AVATARMAP_MODELS (face_detection_short_range.onnx, palm_detection_lite.onnx,
// pose_detection.onnx, pose_landmark_full.onnx); tests needing them skip without them. Each
// test works in its own temporary folder.
#include "capture/onnx/model_cache.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "avatarmap/capture/pose_pipeline.hpp"
#include "capture/onnx/ort_model.hpp"
#include "onnx_support.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;
using test::models_dir;

// The pipelines' process-wide environment (ORT allows one per process).
Ort::Env& env() { return ort_env(); }

Ort::SessionOptions options() {
  Ort::SessionOptions so;
  so.SetIntraOpNumThreads(1);
  so.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
  return so;
}

// Every output of `s` for a fixed pseudo-random input, flattened in output order.
std::vector<float> outputs(Ort::Session& s) {
  Ort::AllocatorWithDefaultOptions alloc;
  const std::vector<int64_t> shape = s.GetInputTypeInfo(0).GetTensorTypeAndShapeInfo().GetShape();
  size_t n = 1;
  for (int64_t d : shape) n *= static_cast<size_t>(d);
  std::vector<float> in(n);
  for (size_t i = 0; i < n; ++i) in[i] = static_cast<float>((i * 2654435761u) % 1000) / 500.f - 1.f;
  const Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
  Ort::Value v = Ort::Value::CreateTensor<float>(mem, in.data(), n, shape.data(), shape.size());
  const std::string in_name = s.GetInputNameAllocated(0, alloc).get();
  std::vector<std::string> names;
  for (size_t i = 0; i < s.GetOutputCount(); ++i)
    names.push_back(s.GetOutputNameAllocated(i, alloc).get());
  std::vector<const char*> ptrs;
  for (const std::string& name : names) ptrs.push_back(name.c_str());
  const char* in_ptr = in_name.c_str();
  std::vector<Ort::Value> outs =
      s.Run(Ort::RunOptions{nullptr}, &in_ptr, &v, 1, ptrs.data(), ptrs.size());
  std::vector<float> flat;
  for (Ort::Value& o : outs) {
    const float* p = o.GetTensorData<float>();
    flat.insert(flat.end(), p, p + o.GetTensorTypeAndShapeInfo().GetElementCount());
  }
  return flat;
}

bool same_bytes(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

std::vector<fs::path> files_ending(const fs::path& dir, const std::string& end) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), e; !ec && it != e; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    if (n.size() >= end.size() && n.compare(n.size() - end.size(), end.size(), end) == 0)
      out.push_back(it->path());
  }
  return out;
}

// A temporary folder holding a copy of one model as model.onnx; removed at the end.
struct scratch {
  fs::path dir;
  fs::path model;
  fs::path cache;
  explicit scratch(const std::string& source_name) {
    static int count = 0;
    dir = fs::temp_directory_path() /
          ("avatarmap_model_cache_" + std::to_string(::getpid()) + "_" + std::to_string(count++));
    fs::remove_all(dir);
    fs::create_directories(dir);
    model = dir / "model.onnx";
    cache = dir / "ort-optimized";
    fs::copy_file(models_dir() + "/" + source_name, model);
  }
  ~scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  cached_session open(const fs::path& cache_dir) const {
    return open_cached_session(env(), model.string(), options(), cache_dir.string());
  }
  // The source model without any cache: what every other way must give.
  std::vector<float> reference() const {
    cached_session s = open("");
    EXPECT_EQ(s.use, model_cache_use::off);
    return outputs(*s.session);
  }
};

#define SKIP_WITHOUT(name)                                                    \
  if (models_dir().empty() || !std::ifstream(models_dir() + "/" name).good()) \
  GTEST_SKIP() << "AVATARMAP_MODELS with onnx/" name " is not set"

TEST(model_cache, first_load_makes_the_copy_and_the_second_loads_it) {
  SKIP_WITHOUT("face_detection_short_range.onnx");
  scratch s("face_detection_short_range.onnx");
  const std::vector<float> ref = s.reference();
  ASSERT_FALSE(ref.empty());
  EXPECT_FALSE(fs::exists(s.cache));

  cached_session first = s.open(s.cache);
  EXPECT_EQ(first.use, model_cache_use::made);
  ASSERT_FALSE(first.cache_path.empty());
  EXPECT_TRUE(fs::is_regular_file(first.cache_path));
  EXPECT_EQ(fs::path(first.cache_path).filename().string(),
            "model." + model_cache_key(s.model.string()) + ".onnx");
  EXPECT_EQ(files_ending(s.cache, ".data").size(), 1u);
  EXPECT_TRUE(files_ending(s.cache, ".tmp").empty());
  EXPECT_TRUE(same_bytes(outputs(*first.session), ref));

  cached_session second = s.open(s.cache);
  EXPECT_EQ(second.use, model_cache_use::hit);
  EXPECT_EQ(second.cache_path, first.cache_path);
  EXPECT_TRUE(same_bytes(outputs(*second.session), ref));
  // Loading changes nothing in the folder.
  EXPECT_EQ(files_ending(s.cache, ".onnx").size(), 1u);
  EXPECT_EQ(files_ending(s.cache, ".data").size(), 1u);
}

TEST(model_cache, a_truncated_or_corrupt_copy_is_made_again) {
  SKIP_WITHOUT("face_detection_short_range.onnx");
  scratch s("face_detection_short_range.onnx");
  const std::vector<float> ref = s.reference();
  const std::string copy = s.open(s.cache).cache_path;
  ASSERT_FALSE(copy.empty());

  // The graph cut in half.
  fs::resize_file(copy, fs::file_size(copy) / 2);
  cached_session a = s.open(s.cache);
  EXPECT_EQ(a.use, model_cache_use::remade);
  EXPECT_TRUE(same_bytes(outputs(*a.session), ref));
  EXPECT_EQ(s.open(s.cache).use, model_cache_use::hit);

  // The weights cut short (every data file: the graph refers to one of them).
  for (const fs::path& d : files_ending(s.cache, ".data")) fs::resize_file(d, 100);
  cached_session b = s.open(s.cache);
  EXPECT_EQ(b.use, model_cache_use::remade);
  EXPECT_TRUE(same_bytes(outputs(*b.session), ref));

  // Not a model at all, then an empty file.
  std::ofstream(copy, std::ios::binary | std::ios::trunc) << "not an onnx model";
  cached_session c = s.open(s.cache);
  EXPECT_EQ(c.use, model_cache_use::remade);
  EXPECT_TRUE(same_bytes(outputs(*c.session), ref));
  std::ofstream(copy, std::ios::binary | std::ios::trunc).close();
  EXPECT_EQ(s.open(s.cache).use, model_cache_use::remade);

  // Its data file gone.
  for (const fs::path& d : files_ending(s.cache, ".data")) fs::remove(d);
  cached_session e = s.open(s.cache);
  EXPECT_EQ(e.use, model_cache_use::remade);
  EXPECT_TRUE(same_bytes(outputs(*e.session), ref));
  EXPECT_EQ(s.open(s.cache).use, model_cache_use::hit);
}

TEST(model_cache, a_folder_that_cannot_be_written_leaves_the_source_model) {
  SKIP_WITHOUT("face_detection_short_range.onnx");
  scratch s("face_detection_short_range.onnx");
  const std::vector<float> ref = s.reference();
  // A file where the folder's parent should be: the folder cannot be created.
  std::ofstream(s.dir / "a_file") << "x";
  cached_session a = s.open(s.dir / "a_file" / "cache");
  EXPECT_EQ(a.use, model_cache_use::unwritable);
  EXPECT_TRUE(a.cache_path.empty());
  EXPECT_TRUE(same_bytes(outputs(*a.session), ref));
  EXPECT_TRUE(fs::is_regular_file(s.dir / "a_file"));

  // A folder without write permission (root writes anyway: checked only for other users).
  if (::geteuid() != 0) {
    fs::create_directories(s.cache);
    fs::permissions(s.cache, fs::perms::owner_read | fs::perms::owner_exec);
    cached_session b = s.open(s.cache);
    EXPECT_EQ(b.use, model_cache_use::unwritable);
    EXPECT_TRUE(same_bytes(outputs(*b.session), ref));
    EXPECT_TRUE(fs::is_empty(s.cache));
    fs::permissions(s.cache, fs::perms::owner_all);
  }
}

TEST(model_cache, a_bad_source_model_throws_and_leaves_no_files) {
  const fs::path dir =
      fs::temp_directory_path() / ("avatarmap_model_cache_bad_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "bad.onnx", std::ios::binary) << "not an onnx model";
  EXPECT_THROW(
      open_cached_session(env(), (dir / "bad.onnx").string(), options(), (dir / "cache").string()),
      Ort::Exception);
  EXPECT_TRUE(files_ending(dir / "cache", ".tmp").empty());
  EXPECT_TRUE(files_ending(dir / "cache", ".data").empty());
  EXPECT_TRUE(files_ending(dir / "cache", ".onnx").empty());
  fs::remove_all(dir);
}

TEST(model_cache, a_replaced_model_gets_a_new_key_and_never_the_old_copy) {
  SKIP_WITHOUT("palm_detection_lite.onnx");
  SKIP_WITHOUT("face_detection_short_range.onnx");
  scratch s("face_detection_short_range.onnx");
  const std::string key = model_cache_key(s.model.string());
  EXPECT_EQ(key.size(), 16u);
  EXPECT_EQ(model_cache_key(s.model.string()), key);  // stable
  EXPECT_EQ(model_cache_key((s.dir / "missing.onnx").string()), "");
  EXPECT_EQ(s.open(s.cache).use, model_cache_use::made);

  // Replaced as scripts/prepare_capture.sh does: a new file renamed over the old one.
  fs::copy_file(models_dir() + "/palm_detection_lite.onnx", s.dir / "model.onnx.tmp");
  fs::rename(s.dir / "model.onnx.tmp", s.model);
  EXPECT_NE(model_cache_key(s.model.string()), key);
  const std::vector<float> ref = s.reference();
  cached_session a = s.open(s.cache);
  EXPECT_EQ(a.use, model_cache_use::made);
  EXPECT_TRUE(same_bytes(outputs(*a.session), ref));
  EXPECT_EQ(s.open(s.cache).use, model_cache_use::hit);
  EXPECT_EQ(files_ending(s.cache, ".onnx").size(), 2u);  // the old copy stays, unused

  // Rewritten in place (a new modification time): a new key too.
  const std::string before = model_cache_key(s.model.string());
  fs::last_write_time(s.model, fs::last_write_time(s.model) + std::chrono::seconds(1));
  EXPECT_NE(model_cache_key(s.model.string()), before);
}

TEST(model_cache, folder_from_the_environment) {
  const char* old = std::getenv("AVATARMAP_ORT_CACHE");
  const std::string saved = old ? old : "";
  ::unsetenv("AVATARMAP_ORT_CACHE");
  EXPECT_EQ(model_cache_dir("/models/onnx/pose_detection.onnx"), "/models/onnx/ort-optimized");
  ::setenv("AVATARMAP_ORT_CACHE", "/elsewhere", 1);
  EXPECT_EQ(model_cache_dir("/models/onnx/pose_detection.onnx"), "/elsewhere");
  ::setenv("AVATARMAP_ORT_CACHE", "off", 1);
  EXPECT_EQ(model_cache_dir("/models/onnx/pose_detection.onnx"), "");
  ::setenv("AVATARMAP_ORT_CACHE", "0", 1);
  EXPECT_EQ(model_cache_dir("/models/onnx/pose_detection.onnx"), "");
  if (old)
    ::setenv("AVATARMAP_ORT_CACHE", saved.c_str(), 1);
  else
    ::unsetenv("AVATARMAP_ORT_CACHE");
}

TEST(model_cache, load_in_parallel_runs_both_and_reports_the_first_failure) {
  int ran = 0;
  EXPECT_EQ(
      load_in_parallel([&] { return ++ran, std::string(); }, [&] { return ++ran, std::string(); }),
      "");
  EXPECT_EQ(ran, 2);
  EXPECT_EQ(
      load_in_parallel([] { return std::string("first"); }, [] { return std::string("second"); }),
      "first");
  EXPECT_EQ(load_in_parallel([] { return std::string(); }, [] { return std::string("second"); }),
            "second");
  bool second_finished = false;
  try {
    load_in_parallel([]() -> std::string { throw std::runtime_error("first"); },
                     [&] { return second_finished = true, std::string("second"); });
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
  EXPECT_TRUE(second_finished);
  EXPECT_THROW(load_in_parallel([] { return std::string(); },
                                []() -> std::string { throw std::runtime_error("second"); }),
               std::runtime_error);
}

// The whole body pipeline on pose.jpg: the same landmarks, bit for bit, without the cache,
// when it makes the copies and when it loads them.
TEST(model_cache, pose_pipeline_gives_the_same_landmarks_from_the_copies) {
  SKIP_WITHOUT("pose_landmark_full.onnx");
  if (test::test_data_dir().empty()) GTEST_SKIP() << test::k_no_test_data;
  test::loaded_image img;
  ASSERT_TRUE(test::load_image(test::test_data_path("motion/tfjs-models/pose.jpg"), img));
  const fs::path cache =
      fs::temp_directory_path() / ("avatarmap_model_cache_pose_" + std::to_string(::getpid()));
  fs::remove_all(cache);
  const char* old = std::getenv("AVATARMAP_ORT_CACHE");
  const std::string saved = old ? old : "";
  auto run = [&](const std::string& setting) {
    ::setenv("AVATARMAP_ORT_CACHE", setting.c_str(), 1);
    pose_pipeline_options o;
    o.models_dir = models_dir();
    o.static_images = true;
    std::unique_ptr<pose_pipeline> p;
    const status st = pose_pipeline::create(o, p);
    EXPECT_TRUE(st.ok()) << st.message();
    landmark_frame f;
    if (p) EXPECT_EQ(p->process(img.view(), f), pose_result::found);
    std::vector<float> v;
    for (const landmark& l : f.pose) v.insert(v.end(), {l.x, l.y, l.z, l.visibility});
    for (const landmark& l : f.pose_world) v.insert(v.end(), {l.x, l.y, l.z});
    return v;
  };
  const std::vector<float> plain = run("off");
  const std::vector<float> made = run(cache.string());
  EXPECT_EQ(files_ending(cache, ".onnx").size(), 2u);
  const std::vector<float> loaded = run(cache.string());
  if (old)
    ::setenv("AVATARMAP_ORT_CACHE", saved.c_str(), 1);
  else
    ::unsetenv("AVATARMAP_ORT_CACHE");
  fs::remove_all(cache);
  ASSERT_FALSE(plain.empty());
  EXPECT_TRUE(same_bytes(made, plain));
  EXPECT_TRUE(same_bytes(loaded, plain));
}

}  // namespace
}  // namespace avatarmap
