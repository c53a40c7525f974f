// The command line's side of the option tables (avatarmap/core/option_table.hpp): each row
// with a flag is read from the arguments and listed in --help from the table itself, so a
// flag, its range, its default and its help are written once. Flags that are not a field of
// an options struct (-o, --parts, --overlay, ...) are declared as cli_flag lists, with their
// help printed the same way. `animate` takes the capture and convert flag sets as they are
// (flag_specs()).
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "avatarmap/core/option_table.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "cli/cli_args.hpp"

namespace avatarmap::cli {

/// A flag of a command that is not a row of an option table.
struct cli_flag {
  const char* flag;        // "--output"
  const char* alias;       // "-o", or nullptr
  const char* value_name;  // "PATH", or nullptr for a switch
  const char* help;
};

/// --parts LIST (solve, convert and so animate): which of the solver's parts to solve.
inline constexpr const char* k_parts_flag_help =
    "comma list of body,hands,face,root: the parts to solve (default: all); a part left out "
    "stays at rest";

/// Reads --parts LIST into `parts` (unchanged without the flag). False with `error` naming an
/// unknown or empty part.
inline bool parse_parts_flag(args& a, solve_parts& parts, std::string& error) {
  std::string value;
  if (!a.value("--parts", value)) return true;
  solve_parts p{false, false, false, false};
  std::size_t start = 0;
  for (;;) {
    const std::size_t end = value.find(',', start);
    const std::string part = value.substr(start, end == std::string::npos ? end : end - start);
    if (part == "body")
      p.body = true;
    else if (part == "hands")
      p.hands = true;
    else if (part == "face")
      p.face = true;
    else if (part == "root")
      p.hips_translation = true;
    else {
      error = "unknown part '" + part + "' in --parts (body,hands,face,root)";
      return false;
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
  parts = p;
  return true;
}

/// A flag as `animate` and the usage checks see it: its name and whether it takes a value.
struct flag_spec {
  std::string name;
  bool takes_value = false;
  std::string help;  // its help line(s); empty for an alias or a switch listed with another
};

/// One help line (or more, wrapped at 92 columns): "  FLAGS  HELP" with HELP from column 24.
inline std::string help_line(const std::string& flags, const std::string& help) {
  constexpr std::size_t k_column = 24, k_width = 92;
  std::string out = "  " + flags;
  std::size_t col = out.size();
  if (col + 2 > k_column) {
    out += "\n";
    col = 0;
  }
  out.append(k_column - col, ' ');
  col = k_column;
  std::size_t i = 0;
  bool first = true;
  while (i < help.size()) {
    std::size_t end = help.find(' ', i);
    if (end == std::string::npos) end = help.size();
    const std::string word = help.substr(i, end - i);
    if (!first && col + 1 + word.size() > k_width) {
      out += "\n" + std::string(k_column, ' ');
      col = k_column;
      first = true;
    }
    if (!first) {
      out += ' ';
      ++col;
    }
    out += word;
    col += word.size();
    first = false;
    i = end + 1;
  }
  return out + "\n";
}

/// The help lines of `flags`.
template <std::size_t N>
std::string cli_flags_help(const cli_flag (&flags)[N]) {
  std::string out;
  for (const cli_flag& f : flags) {
    std::string name = f.alias ? std::string(f.alias) + ", " + f.flag : std::string(f.flag);
    if (f.value_name) name += std::string(" ") + f.value_name;
    out += help_line(name, f.help);
  }
  return out;
}

/// Whether the row's flag is among `only` (every row when `only` is empty): a command that
/// takes some of a table's flags names them.
template <class O>
bool row_taken(const option_row<O>& r, std::initializer_list<const char*> only) {
  if (r.flag == nullptr && r.negation == nullptr) return false;
  if (only.size() == 0) return true;
  for (const char* f : only)
    if ((r.flag && std::string(f) == r.flag) || (r.negation && std::string(f) == r.negation))
      return true;
  return false;
}

/// The help line(s) of one row with a flag, with its default as `start` holds it (the
/// command's own defaults) and its range.
template <class O>
std::string option_row_help(const option_row<O>& r, const O& start) {
  std::string name;
  if (r.flag) name = r.flag;
  if (r.negation) name += (name.empty() ? "" : " / ") + std::string(r.negation);
  std::string help = r.help_text;
  if (r.kind == option_kind::choice) {
    std::string list;
    for (int i = 0; i <= static_cast<int>(r.hi); ++i)
      list += (i ? "|" : "") + option_choice_name(r, i);
    name += " " + list;
    help += " (default " + option_value_text(r, r.get(start)) + ")";
  } else if (r.kind == option_kind::text) {
    name += std::string(" ") + (r.value_name ? r.value_name : "TEXT");
  } else if (r.kind == option_kind::boolean) {
    if (r.flag && r.negation) help += std::string(" (default ") + (r.get(start) ? "on)" : "off)");
  } else {
    name += std::string(" ") + (r.value_name ? r.value_name : "N");
    help += " (default " + option_value_text(r, r.get(start)) + "; " + option_range_text(r) + ")";
  }
  return help_line(name, help);
}

/// The help lines of the rows of `table` that have a flag (among `only`; option_row_help).
template <class O, std::size_t N>
std::string option_flags_help(const option_row<O> (&table)[N], const O& start,
                              std::initializer_list<const char*> only = {}) {
  std::string out;
  for (const option_row<O>& r : table)
    if (row_taken(r, only)) out += option_row_help(r, start);
  return out;
}

/// Reads every flag of `table` (among `only`) present in `a` into `o`. False with `error`
/// naming the flag for a value that is malformed or out of the row's range.
template <class O, std::size_t N>
bool parse_option_flags(args& a, const option_row<O> (&table)[N], O& o, std::string& error,
                        std::initializer_list<const char*> only = {}) {
  for (const option_row<O>& r : table) {
    if (!row_taken(r, only)) continue;
    switch (r.kind) {
      case option_kind::boolean:
        if (r.flag && a.flag(r.flag)) r.set(o, 1.0);
        if (r.negation && a.flag(r.negation)) r.set(o, 0.0);
        break;
      case option_kind::integer: {
        long long v = 0;
        if (a.integer(r.flag, v, static_cast<long long>(r.lo), static_cast<long long>(r.hi)))
          r.set(o, static_cast<double>(v));
        break;
      }
      case option_kind::number: {
        double v = 0.0;
        if (!a.number(r.flag, v)) break;
        if (!option_accepts(r, v)) {
          error = option_range_message(r, r.flag, v);
          return false;
        }
        r.set(o, v);
        break;
      }
      case option_kind::choice: {
        std::string s;
        if (!a.value(r.flag, s)) break;
        const int i = option_choice_index(r, s);
        if (i < 0) {
          error = std::string(r.flag) + " is " + option_range_text(r) + ", got '" + s + "'";
          return false;
        }
        r.set(o, i);
        break;
      }
      case option_kind::text: {
        std::string s;
        if (a.value(r.flag, s)) r.set_text(o, s);
        break;
      }
    }
    if (!a.error().empty()) {
      error = a.error();
      return false;
    }
  }
  return true;
}

/// Appends the flags of `table` to `out` with their help lines (defaults as `start` holds
/// them), for animate and the usage checks.
template <class O, std::size_t N>
void add_flag_specs(const option_row<O> (&table)[N], const O& start, std::vector<flag_spec>& out,
                    std::initializer_list<const char*> only = {}) {
  for (const option_row<O>& r : table) {
    if (!row_taken(r, only)) continue;
    const std::string help = option_row_help(r, start);
    if (r.flag) out.push_back({r.flag, r.kind != option_kind::boolean, help});
    if (r.negation) out.push_back({r.negation, false, r.flag ? std::string() : help});
  }
}
template <std::size_t N>
void add_flag_specs(const cli_flag (&flags)[N], std::vector<flag_spec>& out) {
  for (std::size_t i = 0; i < N; ++i) {
    const cli_flag& f = flags[i];
    const cli_flag one[1] = {f};
    out.push_back({f.flag, f.value_name != nullptr, cli_flags_help(one)});
    if (f.alias) out.push_back({f.alias, f.value_name != nullptr, std::string()});
  }
}

}  // namespace avatarmap::cli
