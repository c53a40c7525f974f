// io/resources.hpp: the one lookup order of the shipped folders (explicit argument →
// environment → installed location → source tree), with temporary folders and setenv.
#include "avatarmap/io/resources.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

// Sets (or unsets, for nullptr) an environment variable for one test and restores it.
class scoped_env {
 public:
  scoped_env(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) {
      had_ = true;
      old_ = old;
    }
    if (value != nullptr)
      ::setenv(name, value, 1);
    else
      ::unsetenv(name);
  }
  ~scoped_env() {
    if (had_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
  }
  scoped_env(const scoped_env&) = delete;
  scoped_env& operator=(const scoped_env&) = delete;

 private:
  const char* name_;
  bool had_ = false;
  std::string old_;
};

// The folder of a "FOLDER (RULE)..." entry of resource_lookup::tried.
std::string tried_folder(const std::string& entry) { return entry.substr(0, entry.rfind(" (")); }

TEST(Resources, ExplicitFolderWinsOverTheEnvironmentAndIsTakenUnchecked) {
  test::temp_dir env_dir("resources_env");
  scoped_env env("AVATARMAP_MAPPINGS", env_dir.path().string().c_str());
  const resource_lookup r = find_resource(resource::mappings, "/no/such/folder");
  EXPECT_EQ(r.folder, "/no/such/folder");
  EXPECT_EQ(r.source, "argument");
  ASSERT_EQ(r.tried.size(), 1u);
}

TEST(Resources, EnvironmentWinsOverInstalledAndSourceTree) {
  test::temp_dir dir("resources_env");
  for (resource kind : {resource::mappings, resource::viewer_page, resource::viewer_modules}) {
    scoped_env env(resource_environment(kind), dir.path().string().c_str());
    const resource_lookup r = find_resource(kind);
    EXPECT_EQ(r.folder, dir.path().string()) << resource_name(kind);
    EXPECT_EQ(r.source, std::string("environment ") + resource_environment(kind));
  }
  // The models variable names the models cache; the models are its onnx/ folder, named even
  // when it does not exist (the user asked for it: the estimator then says what is missing).
  scoped_env env("AVATARMAP_MODELS", dir.path().string().c_str());
  const resource_lookup r = find_resource(resource::models);
  EXPECT_EQ(r.folder, dir.path().string() + "/onnx");
  EXPECT_EQ(r.source, "environment AVATARMAP_MODELS");
}

TEST(Resources, EmptyEnvironmentVariableIsIgnored) {
  scoped_env env("AVATARMAP_MAPPINGS", "");
  const resource_lookup r = find_resource(resource::mappings);
  EXPECT_NE(r.source, "environment AVATARMAP_MAPPINGS");
  for (const std::string& t : r.tried) EXPECT_EQ(t.find("environment"), std::string::npos) << t;
}

TEST(Resources, SourceTreeWhenNothingElseIsThere) {
  // ctest gives the tests the source tree they were built from.
  const char* source = std::getenv("AVATARMAP_SOURCE_DIR");
  if (source == nullptr || *source == '\0') GTEST_SKIP() << "AVATARMAP_SOURCE_DIR is not set";
  scoped_env env("AVATARMAP_MAPPINGS", nullptr);
  const resource_lookup r = find_resource(resource::mappings);
  ASSERT_FALSE(r.tried.empty());
  // The installed candidate is looked at first (beside this executable: none in a build
  // tree), then the source tree.
  EXPECT_NE(r.tried.front().find("(installed): not a folder"), std::string::npos)
      << r.tried.front();
  EXPECT_EQ(r.source, "source tree");
  EXPECT_TRUE(fs::equivalent(r.folder, fs::path(source) / "mappings")) << r.folder;
  EXPECT_TRUE(fs::exists(fs::path(r.folder) / "mixamo.json"));
}

TEST(Resources, InstalledBeforeSourceTree) {
  // The installed candidate lies beside this executable (BINDIR/../share/avatarmap/...); a
  // build tree has none, so make one for the moment of the test: an installed tool must take
  // its own tables even when the source tree it was built from is still there.
  scoped_env env("AVATARMAP_VIEWER_PAGE", nullptr);
  const resource_lookup before = find_resource(resource::viewer_page);
  ASSERT_FALSE(before.tried.empty());
  const std::string first = before.tried.front();
  ASSERT_NE(first.find("(installed): not a folder"), std::string::npos)
      << "an installed viewer page is already beside this executable: " << first;
  const fs::path installed = tried_folder(first);
  std::error_code ec;
  // Remove only what this test creates: the folders that did not exist.
  fs::path top = installed;
  while (!fs::exists(top.parent_path())) top = top.parent_path();
  ASSERT_TRUE(fs::create_directories(installed, ec)) << installed << ": " << ec.message();
  const resource_lookup after = find_resource(resource::viewer_page);
  fs::remove_all(top, ec);
  EXPECT_EQ(after.source, "installed");
  EXPECT_EQ(after.folder, installed.string());
  EXPECT_EQ(after.tried.size(), 1u);
  // And, removed again, the next candidate is used.
  const resource_lookup again = find_resource(resource::viewer_page);
  EXPECT_NE(again.source, "installed");
}

TEST(Resources, NamesAndVariables) {
  EXPECT_STREQ(resource_name(resource::mappings), "mappings");
  EXPECT_STREQ(resource_name(resource::viewer_modules), "viewer modules");
  EXPECT_STREQ(resource_environment(resource::models), "AVATARMAP_MODELS");
  EXPECT_STREQ(resource_environment(resource::viewer_page), "AVATARMAP_VIEWER_PAGE");
}

}  // namespace
}  // namespace avatarmap
