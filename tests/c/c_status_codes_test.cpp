// The one mapping from a library status's code to avm_status (bindings/c/src/c_guard.hpp's
// avm_code), pinned for every code: one to one, each code to the AVM_ERROR_* of the same
// name, and no two codes to the same avm_status. c_guard.cpp is compiled into this test (the
// library exports only avm_* symbols).
#include <gtest/gtest.h>

#include <set>

#include "c_guard.hpp"

namespace avatarmap::c_api {
namespace {

TEST(c_status_codes, every_code_maps_to_the_avm_status_of_its_name) {
  struct pair {
    status_code code;
    avm_status want;
  };
  const pair all[] = {
      {status_code::ok, AVM_OK},
      {status_code::invalid_argument, AVM_ERROR_INVALID_ARGUMENT},
      {status_code::io, AVM_ERROR_IO},
      {status_code::parse, AVM_ERROR_PARSE},
      {status_code::unsupported, AVM_ERROR_UNSUPPORTED},
      {status_code::out_of_memory, AVM_ERROR_OUT_OF_MEMORY},
      {status_code::internal, AVM_ERROR_INTERNAL},
  };
  std::set<int> seen;
  for (const pair& p : all) {
    EXPECT_EQ(avm_code(p.code), p.want) << status_code_name(p.code);
    seen.insert(static_cast<int>(avm_code(p.code)));
    // The status overload reads the status's code.
    const status s = p.code == status_code::ok ? status{} : status::failure(p.code, "m");
    EXPECT_EQ(avm_code(s), p.want) << status_code_name(p.code);
  }
  EXPECT_EQ(seen.size(), sizeof all / sizeof all[0]);  // one to one
  // AVM_ERROR_END_OF_FILE is no failure: no code maps to it.
  EXPECT_EQ(seen.count(AVM_ERROR_END_OF_FILE), 0u);
  // Every other avm_status is reached: the two enumerations have the same failures.
  for (int s = AVM_OK; s <= AVM_ERROR_INTERNAL; ++s)
    if (s != AVM_ERROR_END_OF_FILE) EXPECT_EQ(seen.count(s), 1u) << s;
}

}  // namespace
}  // namespace avatarmap::c_api
