// Options declared once: a table per option set, one row per option with its name (the field's
// name in the C struct and the Python mirror), kind, range, default, help text and accessor.
// From the table come the library's range checks (check_options: one message format), the
// command line's flags and their help (src/cli/option_flags.hpp), and the JSON that
// `avatarmap options --json` prints, against which tests/python/test_options.py checks the C
// API's defaults (avm_*_options_init) and the Python package's ctypes mirrors.
//
// A table is a constexpr array next to its options struct (solve/solver_options.hpp,
// time/filter_option_table.hpp, capture/estimator.hpp, media/video_source.hpp, ...). The
// default of a row is the struct's own (a default-constructed struct), unless the row says
// defaults_to(v): the value every front end (CLI, C, Python) starts from where the struct's
// bare default differs (e.g. two model threads). Header-only; nothing here allocates except
// the texts of messages.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// What values an option takes.
enum class option_kind : unsigned char {
  boolean,  ///< 0 or 1 (the C struct's int32_t flag, a CLI switch)
  integer,  ///< a whole number in [lo, hi]
  number,   ///< a finite number in the row's range
  choice,   ///< one of the names in `choices` ("lite|full|heavy"); stored as its index
  text,     ///< a string (a folder, a pixel format); no range
};

namespace option_detail {

template <class T>
constexpr double to_number(const T& v) {
  if constexpr (std::is_enum_v<T>)
    return static_cast<double>(static_cast<std::underlying_type_t<T>>(v));
  else
    return static_cast<double>(v);
}

template <class T>
constexpr void assign(T& field, double v) {
  if constexpr (std::is_enum_v<T>)
    field = static_cast<T>(static_cast<std::underlying_type_t<T>>(v));
  else if constexpr (std::is_same_v<T, bool>)
    field = v != 0.0;
  else
    field = static_cast<T>(v);
}

}  // namespace option_detail

/// The accessor pair of a numeric field (bool, int, float, double or enum) of `type`: the
/// arguments an option_row's constructor takes after the name.
#define AVATARMAP_OPTION_FIELD(type, member)                                     \
  [](const type& o) { return ::avatarmap::option_detail::to_number(o.member); }, \
      [](type& o, double v) { ::avatarmap::option_detail::assign(o.member, v); }

/// The accessor pair of a std::string field of `type`.
#define AVATARMAP_OPTION_TEXT(type, member)                     \
  [](const type& o) -> const std::string& { return o.member; }, \
      [](type& o, const std::string& v) { o.member = v; }

/// One option of the option set `O`. Built with its name and accessors, then the builder
/// calls below (each returns a changed copy, so a row is one constexpr expression).
template <class O>
struct option_row {
  using options_type = O;
  using getter = double (*)(const O&);
  using setter = void (*)(O&, double);
  using text_getter = const std::string& (*)(const O&);
  using text_setter = void (*)(O&, const std::string&);

  /// The field's name in the C struct and the Python mirror ("rotation_min_cutoff"); for an
  /// option the C API does not have (in_c false), the library field's name.
  const char* name = "";
  option_kind kind = option_kind::number;
  getter get = nullptr;
  setter set = nullptr;
  text_getter get_text = nullptr;
  text_setter set_text = nullptr;
  /// integer and number: the range (infinite ends allowed for numbers).
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  /// number: 0 is also accepted, outside the range ("0 = estimate").
  bool zero_allowed = false;
  /// choice: the names, '|'-separated, in the order of their stored values.
  const char* choice_list = nullptr;
  /// The front ends' default when it is not the struct's (defaults_to()).
  bool has_default = false;
  double default_number = 0.0;
  /// The command line's flag ("--beta"), nullptr when the command line does not take it;
  /// `negation` the switch that turns a boolean off ("--no-hands"); `value_name` the value's
  /// name in the help ("HZ").
  const char* flag = nullptr;
  const char* negation = nullptr;
  const char* value_name = nullptr;
  /// One sentence or two; the default and the range are appended where the help is printed.
  const char* help_text = "";
  /// Whether the C struct (and so the Python mirror) has a field of this name.
  bool in_c = true;

  constexpr option_row(const char* n, getter g, setter s) : name(n), get(g), set(s) {}
  constexpr option_row(const char* n, text_getter g, text_setter s)
      : name(n), kind(option_kind::text), get_text(g), set_text(s) {}

  constexpr option_row boolean() const {
    option_row r = *this;
    r.kind = option_kind::boolean;
    r.lo = 0;
    r.hi = 1;
    return r;
  }
  constexpr option_row integer(double low, double high) const {
    option_row r = *this;
    r.kind = option_kind::integer;
    r.lo = low;
    r.hi = high;
    return r;
  }
  /// A number in [low, high]; `low_open` / `high_open` exclude that end.
  constexpr option_row number(double low, double high, bool low_open = false,
                              bool high_open = false) const {
    option_row r = *this;
    r.kind = option_kind::number;
    r.lo = low;
    r.hi = high;
    r.lo_open = low_open;
    r.hi_open = high_open;
    return r;
  }
  constexpr option_row or_zero() const {
    option_row r = *this;
    r.zero_allowed = true;
    return r;
  }
  constexpr option_row choices(const char* list) const {
    option_row r = *this;
    r.kind = option_kind::choice;
    r.choice_list = list;
    r.lo = 0;
    r.hi = static_cast<double>(count_choices(list) - 1);
    return r;
  }
  constexpr option_row defaults_to(double v) const {
    option_row r = *this;
    r.has_default = true;
    r.default_number = v;
    return r;
  }
  constexpr option_row cli(const char* f, const char* value = nullptr,
                           const char* off = nullptr) const {
    option_row r = *this;
    r.flag = f;
    r.value_name = value;
    r.negation = off;
    return r;
  }
  constexpr option_row help(const char* text) const {
    option_row r = *this;
    r.help_text = text;
    return r;
  }
  constexpr option_row not_in_c() const {
    option_row r = *this;
    r.in_c = false;
    return r;
  }

  static constexpr int count_choices(const char* list) {
    int n = 1;
    for (const char* c = list; *c != '\0'; ++c) n += *c == '|';
    return n;
  }
};

/// The choice names of `r` as a vector-free walk: the name of value `index` ("" when none).
template <class O>
std::string option_choice_name(const option_row<O>& r, int index) {
  if (r.choice_list == nullptr || index < 0) return {};
  const char* c = r.choice_list;
  for (int i = 0; i < index; ++i) {
    c = std::strchr(c, '|');
    if (c == nullptr) return {};
    ++c;
  }
  const char* end = std::strchr(c, '|');
  return end == nullptr ? std::string(c) : std::string(c, static_cast<std::size_t>(end - c));
}

/// The stored value of the choice named `name`, or -1.
template <class O>
int option_choice_index(const option_row<O>& r, const std::string& name) {
  for (int i = 0; i <= static_cast<int>(r.hi); ++i)
    if (option_choice_name(r, i) == name) return i;
  return -1;
}

/// Whether `v` is a value `r` accepts (never for a text row).
template <class O>
bool option_accepts(const option_row<O>& r, double v) {
  if (!std::isfinite(v)) return false;
  switch (r.kind) {
    case option_kind::boolean:
      return v == 0.0 || v == 1.0;
    case option_kind::integer:
    case option_kind::choice:
      return v == std::floor(v) && v >= r.lo && v <= r.hi;
    case option_kind::number:
      if (r.zero_allowed && v == 0.0) return true;
      return (r.lo_open ? v > r.lo : v >= r.lo) && (r.hi_open ? v < r.hi : v <= r.hi);
    case option_kind::text:
      break;
  }
  return false;
}

/// A number as the tables print it ("1000", "0.7", "-inf").
inline std::string option_number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

namespace option_detail {

// An end of a range as printed: "%g", rounded inwards (to hundredths) when "%g" would print a
// bound the range does not include (6.6666665 as "6.66", not "6.66667").
inline std::string bound_text(double v, bool upper) {
  std::string t = option_number_text(v);
  const double printed = std::strtod(t.c_str(), nullptr);
  if (upper ? printed > v : printed < v)
    t = option_number_text(upper ? std::floor(v * 100.0) / 100.0 : std::ceil(v * 100.0) / 100.0);
  return t;
}

}  // namespace option_detail

/// What `r` accepts, as the end of "X must be ...": "in [0, 1]", "in (0, 1000]",
/// "0 or in (1, 179)", "> 0", "in 1..64", "lite, full or heavy", "0 or 1"; "" for text.
template <class O>
std::string option_range_text(const option_row<O>& r) {
  switch (r.kind) {
    case option_kind::boolean:
      return "0 or 1";
    case option_kind::integer:
      return "in " + option_number_text(r.lo) + ".." + option_number_text(r.hi);
    case option_kind::choice: {
      std::string s;
      const int n = static_cast<int>(r.hi) + 1;
      for (int i = 0; i < n; ++i)
        s += (i == 0 ? "" : i + 1 == n ? " or " : ", ") + option_choice_name(r, i);
      return s;
    }
    case option_kind::number: {
      std::string s;
      if (std::isinf(r.hi))
        s = std::string(r.lo_open ? "> " : ">= ") + option_detail::bound_text(r.lo, false);
      else
        s = std::string(r.lo_open ? "in (" : "in [") + option_detail::bound_text(r.lo, false) +
            ", " + option_detail::bound_text(r.hi, true) + (r.hi_open ? ")" : "]");
      return r.zero_allowed ? "0 or " + s : s;
    }
    case option_kind::text:
      break;
  }
  return {};
}

/// `v` as `r` names it: a choice's name, else the number.
template <class O>
std::string option_value_text(const option_row<O>& r, double v) {
  if (r.kind == option_kind::choice && v == std::floor(v)) {
    std::string name = option_choice_name(r, static_cast<int>(v));
    if (!name.empty()) return name;
  }
  return option_number_text(v);
}

/// The front ends' default of a numeric row: defaults_to()'s value, else a default-constructed
/// struct's.
template <class O>
double option_default(const option_row<O>& r) {
  if (r.has_default) return r.default_number;
  return r.get != nullptr ? r.get(O{}) : 0.0;
}

/// The default as text: a number, a choice's name, a string ("" when empty).
template <class O>
std::string option_default_text(const option_row<O>& r) {
  if (r.kind == option_kind::text) return r.get_text != nullptr ? r.get_text(O{}) : std::string();
  return option_value_text(r, option_default(r));
}

/// Sets every row that has defaults_to() to that value (what the front ends start from).
template <class O, std::size_t N>
void apply_option_defaults(const option_row<O> (&table)[N], O& o) {
  for (const option_row<O>& r : table)
    if (r.has_default && r.set != nullptr) r.set(o, r.default_number);
}

/// The one message of a value out of range: "WHAT must be RANGE, got VALUE".
template <class O>
std::string option_range_message(const option_row<O>& r, const std::string& what, double v) {
  return what + " must be " + option_range_text(r) + ", got " + option_value_text(r, v);
}

/// Checks every numeric row of `table` on `o`: the first out of range gives
/// status::error(option_range_message) naming `prefix` + the row's name.
template <class O, std::size_t N>
status check_options(const option_row<O> (&table)[N], const O& o, const std::string& prefix) {
  for (const option_row<O>& r : table) {
    if (r.kind == option_kind::text || r.get == nullptr) continue;
    const double v = r.get(o);
    if (!option_accepts(r, v)) return status::error(option_range_message(r, prefix + r.name, v));
  }
  return {};
}

/// The row of `table` named `name`, or nullptr.
template <class O, std::size_t N>
const option_row<O>* find_option(const option_row<O> (&table)[N], const char* name) {
  for (const option_row<O>& r : table)
    if (std::strcmp(r.name, name) == 0) return &r;
  return nullptr;
}

namespace option_detail {

inline std::string json_string(const char* s) {
  std::string out = "\"";
  for (const char* c = s != nullptr ? s : ""; *c != '\0'; ++c) {
    if (*c == '"' || *c == '\\') {
      out += '\\';
      out += *c;
    } else if (static_cast<unsigned char>(*c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(*c));
      out += buf;
    } else {
      out += *c;
    }
  }
  return out + "\"";
}

inline std::string json_number(double v) {
  if (std::isinf(v)) return v > 0 ? "\"inf\"" : "\"-inf\"";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace option_detail

/// The table as one JSON object: {"set": SET, "c_struct": C_STRUCT (or null), "rows": [{name,
/// kind, min, max, min_open, max_open, zero_allowed, choices, default, flag, negation, help,
/// in_c}, ...]} (infinite ends as "inf"/"-inf"; a text row's default is its string).
template <class O, std::size_t N>
std::string option_table_json(const char* set, const char* c_struct,
                              const option_row<O> (&table)[N]) {
  using option_detail::json_number;
  using option_detail::json_string;
  static const char* const kinds[] = {"boolean", "integer", "number", "choice", "text"};
  std::string s = "{\"set\": " + json_string(set) +
                  ", \"c_struct\": " + (c_struct ? json_string(c_struct) : "null") +
                  ", \"rows\": [";
  for (std::size_t i = 0; i < N; ++i) {
    const option_row<O>& r = table[i];
    s += i == 0 ? "\n  {" : ",\n  {";
    s += "\"name\": " + json_string(r.name);
    s += ", \"kind\": " + json_string(kinds[static_cast<int>(r.kind)]);
    if (r.kind != option_kind::text) {
      s += ", \"min\": " + json_number(r.lo) + ", \"max\": " + json_number(r.hi);
      s += std::string(", \"min_open\": ") + (r.lo_open ? "true" : "false");
      s += std::string(", \"max_open\": ") + (r.hi_open ? "true" : "false");
      s += std::string(", \"zero_allowed\": ") + (r.zero_allowed ? "true" : "false");
      s += ", \"default\": " + json_number(option_default(r));
    } else {
      s += ", \"default\": " + json_string(option_default_text(r).c_str());
    }
    if (r.kind == option_kind::choice) s += ", \"choices\": " + json_string(r.choice_list);
    s += ", \"flag\": " + (r.flag ? json_string(r.flag) : std::string("null"));
    s += ", \"negation\": " + (r.negation ? json_string(r.negation) : std::string("null"));
    s += std::string(", \"in_c\": ") + (r.in_c ? "true" : "false");
    s += ", \"help\": " + json_string(r.help_text) + "}";
  }
  return s + "\n]}";
}

}  // namespace avatarmap
