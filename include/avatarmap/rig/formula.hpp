// Compiled "function expressions" of mapping tables: a formula over the proxy's Euler angles
// x, y, z (radians), compiled once into a small stack-machine program and evaluated per frame
// without allocating. Grammar, precedence and limits: docs/mappings.md ("Formulas").
//
//   formula f;
//   status s = compile_formula("x*0.5 + Math.sin(y)", f);   // load time: may fail
//   float v = f.eval(x, y, z);                               // per frame: never fails
//
// The language is the arithmetic subset of the JavaScript that SysMocap's binding tables use
// (evaluated there with eval()): numbers (12, .5, 1e-3), x y z, pi / PI / Math.PI,
// + - * / (also written × U+00D7, ÷ U+00F7 and − U+2212), unary + and -, parentheses and the
// functions sin cos tan asin acos atan atan2 abs min max clamp sqrt, each optionally written
// with SysMocap's "Math." prefix. Everything else (assignments, other names, statements) is
// rejected at compile time.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// A compiled formula: an immutable flat program of at most k_max_ops instructions needing at
/// most k_max_depth stack slots. A default-constructed formula is empty and evaluates to 0.
/// A plain value (no heap, trivially copyable, ~520 bytes); eval is const and thread-safe.
class formula {
 public:
  /// Longest program (after constant folding), in instructions.
  static constexpr int k_max_ops = 64;
  /// Deepest value stack the program may need.
  static constexpr int k_max_depth = 16;
  /// Deepest nesting of parentheses and function calls the parser accepts.
  static constexpr int k_max_nesting = 32;

  enum class op : std::uint8_t {
    push_const,  // push value
    push_x,
    push_y,
    push_z,
    neg,
    add,
    sub,
    mul,
    div,
    sin,
    cos,
    tan,
    asin,
    acos,
    atan,
    abs,
    sqrt,
    atan2,  // atan2(a, b): a is the first argument (y in C's atan2(y, x))
    min,
    max,
    clamp,  // clamp(v, lo, hi) = min(max(v, lo), hi)
  };
  struct instruction {
    op code = op::push_const;
    float value = 0.f;  // push_const only
  };

  /// Value of the formula at proxy Euler angles (x, y, z), radians. Never allocates, never
  /// fails. IEEE arithmetic in float: division by zero gives +-inf, 0/0 and sqrt/asin/acos
  /// outside their domain give NaN, and non-finite inputs propagate. The result is returned
  /// as computed: callers that need a finite angle must check it (the rig driver treats a
  /// non-finite channel as missing, like any other non-finite input).
  float eval(float x, float y, float z) const noexcept;

  /// True when nothing is compiled (default-constructed); eval then returns 0.
  bool empty() const noexcept { return size_ == 0; }
  /// Number of instructions.
  int size() const noexcept { return size_; }
  /// Stack slots eval needs (computed at compile time, <= k_max_depth).
  int max_depth() const noexcept { return depth_; }
  /// The program, for tests and tools.
  const instruction* code() const noexcept { return code_.data(); }
  /// True when the program is a single constant (e.g. "0", "-pi/2"); `out_value` gets it.
  bool is_constant(float& out_value) const noexcept;

 private:
  friend class formula_compiler;
  std::array<instruction, k_max_ops> code_{};
  std::uint8_t size_ = 0;
  std::uint8_t depth_ = 0;
};

/// Compiles `text` into `out`. On failure `out` is left empty and the message reads
/// "column N: <what was expected or found>" with N the 1-based column in characters (UTF-8
/// code points) of `text`. Fails on: empty text, unbalanced parentheses, an unknown name,
/// a malformed number, a function given the wrong number of arguments, text left after a
/// complete expression, a program longer than formula::k_max_ops, one needing more than
/// formula::k_max_depth stack slots, nesting deeper than formula::k_max_nesting, and bytes
/// that are not part of the language. Allocates only for the error message.
status compile_formula(std::string_view text, formula& out);

}  // namespace avatarmap
