#include "avatarmap/rig/formula.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace avatarmap {

namespace {

using op = formula::op;

constexpr float k_pi = 3.14159265358979323846f;

// JavaScript's Math.min/max: NaN when either argument is NaN (std::fmin would drop it).
inline float js_min(float a, float b) {
  if (a != a || b != b) return std::numeric_limits<float>::quiet_NaN();
  return b < a ? b : a;
}
inline float js_max(float a, float b) {
  if (a != a || b != b) return std::numeric_limits<float>::quiet_NaN();
  return b > a ? b : a;
}

// The same functions serve eval and constant folding, so a folded formula gives bit for bit
// what the unfolded program would.
inline float apply_unary(op code, float a) {
  switch (code) {
    case op::neg:
      return -a;
    case op::sin:
      return std::sin(a);
    case op::cos:
      return std::cos(a);
    case op::tan:
      return std::tan(a);
    case op::asin:
      return std::asin(a);
    case op::acos:
      return std::acos(a);
    case op::atan:
      return std::atan(a);
    case op::abs:
      return std::fabs(a);
    case op::sqrt:
      return std::sqrt(a);
    default:
      return a;
  }
}

inline float apply_binary(op code, float a, float b) {
  switch (code) {
    case op::add:
      return a + b;
    case op::sub:
      return a - b;
    case op::mul:
      return a * b;
    case op::div:
      return a / b;
    case op::atan2:
      return std::atan2(a, b);
    case op::min:
      return js_min(a, b);
    case op::max:
      return js_max(a, b);
    default:
      return a;
  }
}

inline float apply_clamp(float v, float lo, float hi) { return js_min(js_max(v, lo), hi); }

int arity_of(op code) {
  switch (code) {
    case op::push_const:
    case op::push_x:
    case op::push_y:
    case op::push_z:
      return 0;
    case op::add:
    case op::sub:
    case op::mul:
    case op::div:
    case op::atan2:
    case op::min:
    case op::max:
      return 2;
    case op::clamp:
      return 3;
    default:
      return 1;
  }
}

struct function_info {
  std::string_view name;
  op code;
  int min_args;
  int max_args;  // -1: any number >= min_args (folded pairwise, like JavaScript's Math.min)
};

constexpr function_info k_functions[] = {
    {"sin", op::sin, 1, 1},     {"cos", op::cos, 1, 1},   {"tan", op::tan, 1, 1},
    {"asin", op::asin, 1, 1},   {"acos", op::acos, 1, 1}, {"atan", op::atan, 1, 1},
    {"atan2", op::atan2, 2, 2}, {"abs", op::abs, 1, 1},   {"sqrt", op::sqrt, 1, 1},
    {"min", op::min, 2, -1},    {"max", op::max, 2, -1},  {"clamp", op::clamp, 3, 3},
};

const function_info* find_function(std::string_view name) {
  for (const function_info& f : k_functions)
    if (f.name == name) return &f;
  return nullptr;
}

bool is_ident_start(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '$';
}
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_ident_char(char c) { return is_ident_start(c) || is_digit(c); }

}  // namespace

// Recursive-descent parser emitting postfix code directly. Nesting is bounded by
// k_max_nesting, so hostile input cannot exhaust the C++ stack.
class formula_compiler {
 public:
  formula_compiler(std::string_view text, formula& out) : t_(text), out_(out) {}

  status run() {
    out_ = formula{};
    bool ok = expression();
    if (ok) {
      skip_space();
      if (pos_ < t_.size()) {
        ok = fail(pos_, t_[pos_] == ')' ? "unbalanced ')': no '(' to close"
                                        : "expected an operator or the end of the formula, found " +
                                              describe_here());
      }
    }
    if (!ok) {
      out_ = formula{};
      return status::error("column " + std::to_string(column(err_pos_)) + ": " + err_);
    }
    out_.depth_ = static_cast<std::uint8_t>(max_depth_);
    return status{};
  }

 private:
  std::string_view t_;
  formula& out_;
  std::size_t pos_ = 0;
  int nesting_ = 0;
  int depth_ = 0;  // values on the stack after the code emitted so far
  int max_depth_ = 0;
  std::string err_;
  std::size_t err_pos_ = 0;

  bool fail(std::size_t at, std::string message) {
    if (err_.empty()) {
      err_ = std::move(message);
      err_pos_ = at;
    }
    return false;
  }

  // 1-based column in code points: UTF-8 continuation bytes do not start a character.
  int column(std::size_t at) const {
    int col = 1;
    for (std::size_t i = 0; i < at && i < t_.size(); ++i)
      if ((static_cast<unsigned char>(t_[i]) & 0xC0) != 0x80) ++col;
    return col;
  }

  std::string describe_here() const {
    if (pos_ >= t_.size()) return "the end of the formula";
    unsigned char c = static_cast<unsigned char>(t_[pos_]);
    if (c >= 0x20 && c < 0x7F) return std::string("'") + t_[pos_] + "'";
    if (c >= 0x80) {
      std::size_t n = 1;
      while (pos_ + n < t_.size() && (static_cast<unsigned char>(t_[pos_ + n]) & 0xC0) == 0x80 &&
             n < 4)
        ++n;
      return "'" + std::string(t_.substr(pos_, n)) + "'";
    }
    char buf[16];
    std::snprintf(buf, sizeof buf, "byte 0x%02X", c);
    return buf;
  }

  void skip_space() {
    while (pos_ < t_.size() &&
           (t_[pos_] == ' ' || t_[pos_] == '\t' || t_[pos_] == '\n' || t_[pos_] == '\r'))
      ++pos_;
  }

  bool starts_with(std::string_view s) const { return t_.substr(pos_, s.size()) == s; }

  // Additive operator at pos_ (after spaces): '+', '-' or U+2212; returns its byte length.
  std::size_t additive(op& out_code) const {
    if (pos_ >= t_.size()) return 0;
    out_code = op::sub;
    if (t_[pos_] == '-') return 1;
    if (starts_with("\xE2\x88\x92")) return 3;  // U+2212 minus sign
    out_code = op::add;
    return t_[pos_] == '+' ? 1 : 0;
  }
  std::size_t multiplicative(op& out_code) const {
    if (pos_ >= t_.size()) return 0;
    if (t_[pos_] == '*') {
      // JavaScript's "**" (power) is not part of the language: say so rather than reporting
      // a confusing unary error on the second '*'.
      out_code = op::mul;
      return pos_ + 1 < t_.size() && t_[pos_ + 1] == '*' ? 0 : 1;
    }
    out_code = op::div;
    if (t_[pos_] == '/') return 1;
    if (starts_with("\xC3\xB7")) return 2;  // U+00F7 division sign
    out_code = op::mul;
    return starts_with("\xC3\x97") ? 2 : 0;  // U+00D7 multiplication sign
  }

  bool emit(op code, float value, std::size_t at) {
    const int arity = arity_of(code);
    depth_ += 1 - arity;
    if (depth_ > max_depth_) max_depth_ = depth_;
    if (max_depth_ > formula::k_max_depth)
      return fail(at, "formula needs more than " + std::to_string(formula::k_max_depth) +
                          " stack slots (too many pending operands)");
    // Constant folding. In postfix code the operands of an operator are complete
    // sub-programs ending right before it; one that ends in push_const is that single push.
    int n = out_.size_;
    auto is_const = [&](int i) { return i >= 0 && out_.code_[i].code == op::push_const; };
    if (arity == 1 && is_const(n - 1)) {
      out_.code_[n - 1].value = apply_unary(code, out_.code_[n - 1].value);
      return true;
    }
    if (arity == 2 && is_const(n - 1) && is_const(n - 2)) {
      out_.code_[n - 2].value =
          apply_binary(code, out_.code_[n - 2].value, out_.code_[n - 1].value);
      out_.size_ = static_cast<std::uint8_t>(n - 1);
      return true;
    }
    if (arity == 3 && is_const(n - 1) && is_const(n - 2) && is_const(n - 3)) {
      out_.code_[n - 3].value =
          apply_clamp(out_.code_[n - 3].value, out_.code_[n - 2].value, out_.code_[n - 1].value);
      out_.size_ = static_cast<std::uint8_t>(n - 2);
      return true;
    }
    if (n >= formula::k_max_ops)
      return fail(
          at, "formula too long (more than " + std::to_string(formula::k_max_ops) + " operations)");
    out_.code_[n] = formula::instruction{code, code == op::push_const ? value : 0.f};
    out_.size_ = static_cast<std::uint8_t>(n + 1);
    return true;
  }

  bool enter(std::size_t at) {
    if (++nesting_ > formula::k_max_nesting)
      return fail(at, "nesting deeper than " + std::to_string(formula::k_max_nesting) +
                          " parentheses or calls");
    return true;
  }

  // expression := term (('+' | '-') term)*
  bool expression() {
    if (!term()) return false;
    for (;;) {
      skip_space();
      op code;
      std::size_t at = pos_, len = additive(code);
      if (len == 0) return true;
      pos_ += len;
      if (!term() || !emit(code, 0.f, at)) return false;
    }
  }

  // term := unary (('*' | '/') unary)*
  bool term() {
    if (!unary()) return false;
    for (;;) {
      skip_space();
      op code;
      std::size_t at = pos_, len = multiplicative(code);
      if (len == 0) return true;
      pos_ += len;
      if (!unary() || !emit(code, 0.f, at)) return false;
    }
  }

  // unary := ('+' | '-')* primary. Signs are counted in a loop (no recursion), so a long
  // chain cannot overflow the stack; an odd number of minus signs emits one negation.
  bool unary() {
    bool negate = false;
    std::size_t first_sign = std::string_view::npos;
    for (;;) {
      skip_space();
      op code;
      std::size_t len = additive(code);
      if (len == 0) break;
      if (first_sign == std::string_view::npos) first_sign = pos_;
      if (code == op::sub) negate = !negate;
      pos_ += len;
    }
    if (!primary()) return false;
    return !negate || emit(op::neg, 0.f, first_sign);
  }

  bool number() {
    const std::size_t start = pos_;
    std::size_t i = pos_;
    int digits = 0;
    while (i < t_.size() && is_digit(t_[i])) ++i, ++digits;
    if (i < t_.size() && t_[i] == '.') {
      ++i;
      while (i < t_.size() && is_digit(t_[i])) ++i, ++digits;
    }
    bool bad = digits == 0;
    if (!bad && i < t_.size() && (t_[i] == 'e' || t_[i] == 'E')) {
      ++i;
      if (i < t_.size() && (t_[i] == '+' || t_[i] == '-')) ++i;
      int exp_digits = 0;
      while (i < t_.size() && is_digit(t_[i])) ++i, ++exp_digits;
      bad = exp_digits == 0;
    }
    // A number glued to a name or another '.' ("2x", "1.2.3") is one malformed token.
    std::size_t end = i;
    while (end < t_.size() && (is_ident_char(t_[end]) || t_[end] == '.')) ++end;
    if (bad || end != i)
      return fail(start, "malformed number '" + std::string(t_.substr(start, end - start)) + "'");
    double v = 0.0;
    auto [ptr, ec] = std::from_chars(t_.data() + start, t_.data() + i, v);
    if (ec != std::errc() || ptr != t_.data() + i || !(std::fabs(v) <= 3.4028234663852886e38))
      return fail(start,
                  "number '" + std::string(t_.substr(start, i - start)) + "' is out of range");
    pos_ = i;
    return emit(op::push_const, static_cast<float>(v), start);
  }

  std::string_view identifier() {
    std::size_t start = pos_;
    while (pos_ < t_.size() && is_ident_char(t_[pos_])) ++pos_;
    return t_.substr(start, pos_ - start);
  }

  bool call(const function_info& f, std::string_view spelled, std::size_t at) {
    skip_space();
    if (pos_ >= t_.size() || t_[pos_] != '(')
      return fail(pos_,
                  "expected '(' after '" + std::string(spelled) + "', found " + describe_here());
    if (!enter(pos_)) return false;
    ++pos_;
    int args = 0;
    skip_space();
    if (pos_ < t_.size() && t_[pos_] == ')') {
      ++pos_;
    } else {
      for (;;) {
        if (!expression()) return false;
        ++args;
        // min/max with more than two arguments: fold pairwise as they arrive.
        if (f.max_args < 0 && args >= 2 && !emit(f.code, 0.f, at)) return false;
        skip_space();
        if (pos_ < t_.size() && t_[pos_] == ',') {
          ++pos_;
          continue;
        }
        if (pos_ < t_.size() && t_[pos_] == ')') {
          ++pos_;
          break;
        }
        return fail(pos_, "expected ',' or ')' in the arguments of '" + std::string(spelled) +
                              "', found " + describe_here());
      }
    }
    --nesting_;
    if (args < f.min_args || (f.max_args >= 0 && args > f.max_args)) {
      std::string want =
          f.max_args < 0 ? "at least " + std::to_string(f.min_args) : std::to_string(f.min_args);
      return fail(at, "'" + std::string(spelled) + "' takes " + want + " argument" +
                          (f.min_args == 1 && f.max_args == 1 ? "" : "s") + ", got " +
                          std::to_string(args));
    }
    if (f.max_args < 0) return true;  // already emitted after each argument
    return emit(f.code, 0.f, at);
  }

  // primary := number | x | y | z | pi | function '(' arguments ')' | '(' expression ')'
  bool primary() {
    skip_space();
    const std::size_t at = pos_;
    if (pos_ >= t_.size())
      return fail(at, "expected a number, a name or '(', found the end of the formula");
    const char c = t_[pos_];
    if (is_digit(c) || c == '.') return number();
    if (c == '(') {
      if (!enter(at)) return false;
      ++pos_;
      if (!expression()) return false;
      skip_space();
      if (pos_ >= t_.size() || t_[pos_] != ')')
        return fail(pos_, "expected ')' to close the '(' at column " + std::to_string(column(at)) +
                              ", found " + describe_here());
      ++pos_;
      --nesting_;
      return true;
    }
    if (!is_ident_start(c))
      return fail(at, "expected a number, a name or '(', found " + describe_here());
    std::string_view name = identifier();
    bool math = false;
    if (name == "Math" && pos_ < t_.size() && t_[pos_] == '.') {
      ++pos_;
      if (pos_ >= t_.size() || !is_ident_start(t_[pos_]))
        return fail(pos_, "expected a name after 'Math.', found " + describe_here());
      name = identifier();
      math = true;
    }
    const std::string_view spelled = t_.substr(at, pos_ - at);
    if (!math && name.size() == 1 && (name[0] == 'x' || name[0] == 'y' || name[0] == 'z'))
      return emit(name[0] == 'x' ? op::push_x : name[0] == 'y' ? op::push_y : op::push_z, 0.f, at);
    if (name == "PI" || (!math && name == "pi")) return emit(op::push_const, k_pi, at);
    if (const function_info* f = find_function(name)) return call(*f, spelled, at);
    return fail(at, "unknown name '" + std::string(spelled) +
                        "' (expected x, y, z, pi, PI, Math.PI or one of the functions sin cos "
                        "tan asin acos atan atan2 abs min max clamp sqrt)");
  }
};

status compile_formula(std::string_view text, formula& out) {
  return formula_compiler(text, out).run();
}

bool formula::is_constant(float& out_value) const noexcept {
  if (size_ != 1 || code_[0].code != op::push_const) return false;
  out_value = code_[0].value;
  return true;
}

float formula::eval(float x, float y, float z) const noexcept {
  float s[k_max_depth];
  int sp = 0;  // number of values on the stack
  const int n = size_;
  for (int i = 0; i < n; ++i) {
    const instruction& in = code_[static_cast<std::size_t>(i)];
    switch (in.code) {
      case op::push_const:
        s[sp++] = in.value;
        break;
      case op::push_x:
        s[sp++] = x;
        break;
      case op::push_y:
        s[sp++] = y;
        break;
      case op::push_z:
        s[sp++] = z;
        break;
      case op::add:
        --sp;
        s[sp - 1] += s[sp];
        break;
      case op::sub:
        --sp;
        s[sp - 1] -= s[sp];
        break;
      case op::mul:
        --sp;
        s[sp - 1] *= s[sp];
        break;
      case op::div:
        --sp;
        s[sp - 1] /= s[sp];
        break;
      case op::atan2:
      case op::min:
      case op::max:
        --sp;
        s[sp - 1] = apply_binary(in.code, s[sp - 1], s[sp]);
        break;
      case op::clamp:
        sp -= 2;
        s[sp - 1] = apply_clamp(s[sp - 1], s[sp], s[sp + 1]);
        break;
      default:  // unary
        s[sp - 1] = apply_unary(in.code, s[sp - 1]);
        break;
    }
  }
  return n > 0 ? s[0] : 0.f;
}

}  // namespace avatarmap
