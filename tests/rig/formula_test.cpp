#include "avatarmap/rig/formula.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace avatarmap;

namespace {

constexpr float k_pi = 3.14159265358979323846f;

// Compiles or fails the test; evaluates at (x, y, z).
float ev(const std::string& text, float x = 0.f, float y = 0.f, float z = 0.f) {
  formula f;
  status s = compile_formula(text, f);
  EXPECT_TRUE(s.ok()) << text << ": " << s.message();
  return f.eval(x, y, z);
}

std::string error_of(const std::string& text) {
  formula f;
  status s = compile_formula(text, f);
  EXPECT_FALSE(s.ok()) << "'" << text << "' compiled";
  EXPECT_TRUE(f.empty()) << "a failed compile leaves the formula empty";
  return s.message();
}

// The message starts with "column N: " and contains `what`.
void expect_error(const std::string& text, int column, const std::string& what) {
  std::string m = error_of(text);
  std::string prefix = "column " + std::to_string(column) + ": ";
  EXPECT_EQ(m.rfind(prefix, 0), 0u) << "'" << text << "' -> " << m;
  EXPECT_NE(m.find(what), std::string::npos) << "'" << text << "' -> " << m;
}

}  // namespace

TEST(formula, variables_and_sysmocap_bindings) {
  EXPECT_FLOAT_EQ(ev("x", 1.f, 2.f, 3.f), 1.f);
  EXPECT_FLOAT_EQ(ev("y", 1.f, 2.f, 3.f), 2.f);
  EXPECT_FLOAT_EQ(ev("z", 1.f, 2.f, 3.f), 3.f);
  EXPECT_FLOAT_EQ(ev("-z", 1.f, 2.f, 3.f), -3.f);
  EXPECT_FLOAT_EQ(ev("-x", 1.f, 2.f, 3.f), -1.f);
  EXPECT_FLOAT_EQ(ev("x*0.5+sin(y)", 1.f, 0.3f, 0.f), 0.5f + std::sin(0.3f));
  EXPECT_FLOAT_EQ(ev(" \t-y \n", 1.f, 2.f, 3.f), -2.f);
}

TEST(formula, numbers) {
  EXPECT_FLOAT_EQ(ev("12"), 12.f);
  EXPECT_FLOAT_EQ(ev(".5"), 0.5f);
  EXPECT_FLOAT_EQ(ev("5."), 5.f);
  EXPECT_FLOAT_EQ(ev("1e-3"), 1e-3f);
  EXPECT_FLOAT_EQ(ev("2.5E+2"), 250.f);
  EXPECT_FLOAT_EQ(ev("1e2"), 100.f);
  EXPECT_FLOAT_EQ(ev("0.000"), 0.f);
}

TEST(formula, constants) {
  EXPECT_FLOAT_EQ(ev("pi"), k_pi);
  EXPECT_FLOAT_EQ(ev("PI"), k_pi);
  EXPECT_FLOAT_EQ(ev("Math.PI"), k_pi);
  EXPECT_FLOAT_EQ(ev("-Math.PI / 2"), -k_pi / 2);
}

TEST(formula, precedence_and_associativity) {
  EXPECT_FLOAT_EQ(ev("2-3-4"), -5.f);  // left-associative
  EXPECT_FLOAT_EQ(ev("2/4/2"), 0.25f);
  EXPECT_FLOAT_EQ(ev("-2*-3"), 6.f);
  EXPECT_FLOAT_EQ(ev("2+3*4"), 14.f);
  EXPECT_FLOAT_EQ(ev("(2+3)*4"), 20.f);
  EXPECT_FLOAT_EQ(ev("2*3+4"), 10.f);
  EXPECT_FLOAT_EQ(ev("8-2*3"), 2.f);
  EXPECT_FLOAT_EQ(ev("1-(2-3)"), 2.f);
  EXPECT_FLOAT_EQ(ev("x-y-z", 10.f, 3.f, 2.f), 5.f);  // with variables, no folding
  EXPECT_FLOAT_EQ(ev("x/y/z", 8.f, 2.f, 2.f), 2.f);
  EXPECT_FLOAT_EQ(ev("-x*-y", 2.f, 3.f), 6.f);
  EXPECT_FLOAT_EQ(ev("x+y*z", 1.f, 2.f, 3.f), 7.f);
  EXPECT_FLOAT_EQ(ev("2-3", 0.f), -1.f);
  EXPECT_FLOAT_EQ(ev("2 - -3"), 5.f);
}

TEST(formula, unary_chains) {
  EXPECT_FLOAT_EQ(ev("--x", 2.f), 2.f);
  EXPECT_FLOAT_EQ(ev("---x", 2.f), -2.f);
  EXPECT_FLOAT_EQ(ev("+x", 2.f), 2.f);
  EXPECT_FLOAT_EQ(ev("-+-+x", 2.f), 2.f);
  EXPECT_FLOAT_EQ(ev("- - - 1"), -1.f);
  EXPECT_FLOAT_EQ(ev("-(x)", 2.f), -2.f);
  EXPECT_FLOAT_EQ(ev("-sin(x)", 0.5f), -std::sin(0.5f));
  // A very long chain is iterative: no recursion, one negation at most.
  std::string chain(10001, '-');
  formula f;
  ASSERT_TRUE(compile_formula(chain + "x", f).ok());
  EXPECT_FLOAT_EQ(f.eval(2.f, 0.f, 0.f), -2.f);
  EXPECT_EQ(f.size(), 2);
}

TEST(formula, unicode_operators) {
  EXPECT_FLOAT_EQ(ev("3\xC3\x97"
                     "4"),
                  12.f);  // 3×4
  EXPECT_FLOAT_EQ(ev("3\xC3\xB7"
                     "4"),
                  0.75f);                           // 3÷4
  EXPECT_FLOAT_EQ(ev("\xE2\x88\x92x", 2.f), -2.f);  // −x (U+2212)
  EXPECT_FLOAT_EQ(ev("5 \xE2\x88\x92 x", 2.f), 3.f);
}

TEST(formula, every_function) {
  const float a = 0.3f, b = -0.7f;
  EXPECT_FLOAT_EQ(ev("sin(x)", a), std::sin(a));
  EXPECT_FLOAT_EQ(ev("cos(x)", a), std::cos(a));
  EXPECT_FLOAT_EQ(ev("tan(x)", a), std::tan(a));
  EXPECT_FLOAT_EQ(ev("asin(x)", a), std::asin(a));
  EXPECT_FLOAT_EQ(ev("acos(x)", a), std::acos(a));
  EXPECT_FLOAT_EQ(ev("atan(x)", a), std::atan(a));
  EXPECT_FLOAT_EQ(ev("atan2(x, y)", a, b), std::atan2(a, b));
  EXPECT_FLOAT_EQ(ev("abs(y)", a, b), std::fabs(b));
  EXPECT_FLOAT_EQ(ev("sqrt(x)", a), std::sqrt(a));
  EXPECT_FLOAT_EQ(ev("min(x, y)", a, b), b);
  EXPECT_FLOAT_EQ(ev("max(x, y)", a, b), a);
  EXPECT_FLOAT_EQ(ev("min(x, y, z)", 1.f, 2.f, -3.f), -3.f);
  EXPECT_FLOAT_EQ(ev("max(x, y, z, 10)", 1.f, 2.f, -3.f), 10.f);
  EXPECT_FLOAT_EQ(ev("clamp(x, -1, 1)", 2.f), 1.f);
  EXPECT_FLOAT_EQ(ev("clamp(x, -1, 1)", -2.f), -1.f);
  EXPECT_FLOAT_EQ(ev("clamp(x, -1, 1)", 0.25f), 0.25f);
  // SysMocap's spelling.
  EXPECT_FLOAT_EQ(ev("Math.sin(x)", a), std::sin(a));
  EXPECT_FLOAT_EQ(ev("Math.atan2(x,y)", a, b), std::atan2(a, b));
  EXPECT_FLOAT_EQ(ev("Math.abs(y)+Math.min(x,1)", a, b), std::fabs(b) + a);
  EXPECT_FLOAT_EQ(ev("Math.max(x, Math.PI)", a), k_pi);
  // Nested calls and constant arguments (folded at compile time).
  EXPECT_FLOAT_EQ(ev("sin(cos(x))", a), std::sin(std::cos(a)));
  EXPECT_FLOAT_EQ(ev("sqrt(16)"), 4.f);
  EXPECT_FLOAT_EQ(ev("clamp(5, 0, 1)"), 1.f);
}

TEST(formula, constant_folding_matches_evaluation) {
  formula f;
  ASSERT_TRUE(compile_formula("-2*-3 + sin(pi/2)", f).ok());
  float v = 0.f;
  EXPECT_TRUE(f.is_constant(v));
  EXPECT_FLOAT_EQ(v, 7.f);
  ASSERT_TRUE(compile_formula("-z", f).ok());
  EXPECT_FALSE(f.is_constant(v));
  EXPECT_EQ(f.size(), 2);
  EXPECT_EQ(f.max_depth(), 1);
  ASSERT_TRUE(compile_formula("x*0.5+sin(y)", f).ok());
  EXPECT_EQ(f.size(), 6);
  EXPECT_EQ(f.max_depth(), 2);
}

TEST(formula, non_finite_results_are_returned_as_computed) {
  // Documented: IEEE semantics, callers sanitise.
  EXPECT_EQ(ev("1/0"), std::numeric_limits<float>::infinity());
  EXPECT_EQ(ev("-1/0"), -std::numeric_limits<float>::infinity());
  EXPECT_EQ(ev("x/y", 1.f, 0.f), std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(ev("0/0")));
  EXPECT_TRUE(std::isnan(ev("sqrt(x)", -1.f)));
  EXPECT_TRUE(std::isnan(ev("asin(2)")));
  EXPECT_TRUE(std::isnan(ev("x", std::nanf(""))));
  // Like JavaScript's Math.min/max, NaN wins.
  EXPECT_TRUE(std::isnan(ev("min(x, 1)", std::nanf(""))));
  EXPECT_TRUE(std::isnan(ev("max(1, x)", std::nanf(""))));
}

TEST(formula, empty_formula_evaluates_to_zero) {
  formula f;
  EXPECT_TRUE(f.empty());
  EXPECT_EQ(f.eval(1.f, 2.f, 3.f), 0.f);
}

TEST(formula, error_empty) {
  expect_error("", 1, "found the end of the formula");
  expect_error("   ", 4, "found the end of the formula");
}

TEST(formula, error_unbalanced_parentheses) {
  expect_error("(x", 3, "expected ')' to close the '(' at column 1");
  expect_error("((x)", 5, "expected ')' to close the '(' at column 1");
  expect_error("x)", 2, "unbalanced ')'");
  expect_error("(x))", 4, "unbalanced ')'");
  expect_error(")", 1, "expected a number, a name or '(', found ')'");
  expect_error("()", 2, "found ')'");
  expect_error("sin(x", 6, "expected ',' or ')'");
}

TEST(formula, error_unknown_identifier) {
  expect_error("w", 1, "unknown name 'w'");
  expect_error("x + foo", 5, "unknown name 'foo'");
  expect_error("Math.x", 1, "unknown name 'Math.x'");
  expect_error("Math.pi", 1, "unknown name 'Math.pi'");  // JavaScript spells it PI
  expect_error("exp(x)", 1, "unknown name 'exp'");
  expect_error("Math.", 6, "expected a name after 'Math.'");
  expect_error("sin x", 5, "expected '(' after 'sin'");
}

TEST(formula, error_trailing_garbage) {
  expect_error("x y", 3, "expected an operator or the end of the formula, found 'y'");
  expect_error("x;", 2, "found ';'");
  expect_error("x(1)", 2, "found '('");
  expect_error("x ** 2", 3, "found '*'");
  expect_error("x = 1", 3, "found '='");
  // Columns count characters, not bytes: "×" is two bytes.
  expect_error("\xC3\x97x", 1, "found '\xC3\x97'");
  expect_error(
      "2\xC3\x97"
      "3 #",
      5, "found '#'");
}

TEST(formula, error_bad_number) {
  expect_error("1e", 1, "malformed number '1e'");
  expect_error("x+1e+", 3, "malformed number '1e+'");
  expect_error("1.2.3", 1, "malformed number '1.2.3'");
  expect_error("2x", 1, "malformed number '2x'");
  expect_error(".", 1, "malformed number '.'");
  expect_error("1e99", 1, "out of range");
}

TEST(formula, error_wrong_argument_count) {
  expect_error("sin()", 1, "'sin' takes 1 argument, got 0");
  expect_error("sin(x, y)", 1, "'sin' takes 1 argument, got 2");
  expect_error("x + atan2(x)", 5, "'atan2' takes 2 arguments, got 1");
  expect_error("Math.atan2(1,2,3)", 1, "'Math.atan2' takes 2 arguments, got 3");
  expect_error("min(x)", 1, "'min' takes at least 2 arguments, got 1");
  expect_error("clamp(x, 1)", 1, "'clamp' takes 3 arguments, got 2");
  expect_error("sin(x,)", 7, "expected a number");
}

TEST(formula, error_too_long) {
  // 33 variables and 32 additions: 65 operations.
  std::string text = "x";
  for (int i = 0; i < 32; ++i) text += "+x";
  expect_error(text, 64, "formula too long (more than 64 operations)");
  // Exactly 64 fits: 32 pushes, one negation, 31 additions.
  std::string ok = "-x";
  for (int i = 0; i < 31; ++i) ok += "+x";
  formula f;
  ASSERT_TRUE(compile_formula(ok, f).ok());
  EXPECT_EQ(f.size(), formula::k_max_ops);
  EXPECT_FLOAT_EQ(f.eval(1.f, 0.f, 0.f), 30.f);
  // Constants fold, so a long constant sum is short.
  std::string folded = "1";
  for (int i = 0; i < 100; ++i) folded += "+1";
  EXPECT_FLOAT_EQ(ev(folded), 101.f);
}

TEST(formula, error_too_deep) {
  // x+(x+(x+...)) keeps every left operand pending: 17 values.
  std::string text, close;
  for (int i = 0; i < 16; ++i) text += "x+(", close += ")";
  text += "x" + close;
  expect_error(text, 49, "more than 16 stack slots");
  std::string nested(40, '(');
  expect_error(nested + "x" + std::string(40, ')'), 33, "nesting deeper than 32");
  formula f;
  std::string fine = std::string(30, '(') + "x" + std::string(30, ')');
  EXPECT_TRUE(compile_formula(fine, f).ok());
}

TEST(formula, error_stray_bytes) {
  expect_error(std::string("x+\x01", 3), 3, "byte 0x01");
  expect_error(std::string("x\0", 2), 2, "byte 0x00");
  expect_error("x + \xE2\x82\xAC", 5, "found '\xE2\x82\xAC'");  // €
}
