// libFuzzer target: the formula compiler (rig/formula.hpp) on arbitrary bytes. Checks that it
// never crashes, that a failure leaves the formula empty with a "column N: " message inside
// the text, and that a compiled program respects its limits and evaluates.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "avatarmap/rig/formula.hpp"

using namespace avatarmap;

namespace {
void check(bool ok, const char* what) {
  if (!ok) {
    std::fprintf(stderr, "invariant failed: %s\n", what);
    std::abort();
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  formula f;
  status s = compile_formula(text, f);
  if (!s.ok()) {
    check(f.empty(), "a failed compile leaves the formula empty");
    check(s.message().rfind("column ", 0) == 0, "errors start with the column");
    long column = std::strtol(s.message().c_str() + 7, nullptr, 10);
    check(column >= 1 && static_cast<std::size_t>(column) <= size + 1, "column inside the text");
    return 0;
  }
  check(!f.empty(), "a compiled formula is not empty");
  check(f.size() <= formula::k_max_ops, "program length within the limit");
  check(f.max_depth() >= 1 && f.max_depth() <= formula::k_max_depth, "depth within the limit");
  volatile float sink = f.eval(0.1f, -0.2f, 0.3f);
  sink = f.eval(0.f, 0.f, 0.f);
  (void)sink;
  float c = 0.f;
  if (f.is_constant(c)) check(f.size() == 1, "constants are single instructions");
  return 0;
}
