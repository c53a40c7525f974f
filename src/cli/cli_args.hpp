// A small command-line argument scanner for the avatarmap tool: flags, "--name value" and
// "--name=value" options, positionals. Errors are messages for the user, never exceptions.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace avatarmap::cli {

class args {
 public:
  args(int argc, char** argv, int first) {
    for (int i = first; i < argc; ++i) items_.emplace_back(argv[i]);
  }

  /// Removes "--name" and returns true when present.
  bool flag(const std::string& name) {
    for (size_t i = 0; i < items_.size(); ++i) {
      if (items_[i] == name) {
        items_.erase(items_.begin() + static_cast<long>(i));
        return true;
      }
    }
    return false;
  }

  /// Removes "--name VALUE" / "--name=VALUE" (or "-s VALUE" for the short alias) and stores the
  /// value. Returns false when absent; sets error() when the value is missing.
  bool value(const std::string& name, std::string& out, const std::string& alias = "") {
    for (size_t i = 0; i < items_.size(); ++i) {
      const std::string& it = items_[i];
      if (it == name || (!alias.empty() && it == alias)) {
        if (i + 1 >= items_.size()) {
          error_ = "option " + it + " needs a value";
          items_.erase(items_.begin() + static_cast<long>(i));
          return false;
        }
        out = items_[i + 1];
        items_.erase(items_.begin() + static_cast<long>(i),
                     items_.begin() + static_cast<long>(i) + 2);
        return true;
      }
      if (it.rfind(name + "=", 0) == 0) {
        out = it.substr(name.size() + 1);
        items_.erase(items_.begin() + static_cast<long>(i));
        return true;
      }
    }
    return false;
  }

  /// Like value() but parses a finite number; sets error() when it is not one.
  bool number(const std::string& name, double& out) {
    std::string s;
    if (!value(name, s)) return false;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !(v == v) || v > 1e300 || v < -1e300) {
      error_ = "option " + name + " needs a number, got '" + s + "'";
      return false;
    }
    out = v;
    return true;
  }

  /// Like value() but parses a whole number written in decimal (an optional '-', then digits:
  /// no "0x50", "8e1", "80.0" or spaces) within [lo, hi]; sets error() naming the option and
  /// the range when it is not one.
  bool integer(const std::string& name, long long& out, long long lo, long long hi) {
    std::string s;
    if (!value(name, s)) return false;
    const std::size_t first = !s.empty() && s[0] == '-' ? 1 : 0;
    bool digits = s.size() > first && s.size() - first <= 18;
    for (std::size_t i = first; digits && i < s.size(); ++i) digits = s[i] >= '0' && s[i] <= '9';
    const long long v = digits ? std::strtoll(s.c_str(), nullptr, 10) : 0;
    if (!digits || v < lo || v > hi) {
      error_ = "option " + name + " needs a whole number in " + std::to_string(lo) + ".." +
               std::to_string(hi) + ", got '" + s + "'";
      return false;
    }
    out = v;
    return true;
  }
  bool integer(const std::string& name, int& out, int lo, int hi) {
    long long v = 0;
    if (!integer(name, v, lo, hi)) return false;
    out = static_cast<int>(v);
    return true;
  }

  /// What is left after the options were taken; unknown "-x" options are reported by
  /// check_no_options().
  const std::vector<std::string>& rest() const { return items_; }

  /// Fails with a message when an unrecognised option is left.
  bool check_no_options() {
    for (const std::string& it : items_) {
      if (it.size() > 1 && it[0] == '-') {
        error_ = "unknown option " + it + " (see --help)";
        return false;
      }
    }
    return true;
  }

  const std::string& error() const { return error_; }

 private:
  std::vector<std::string> items_;
  std::string error_;
};

/// Parses "WxH" (pixels, each 1..100000, nothing else on the line); false when malformed.
inline bool parse_image_size(const std::string& s, int& out_width, int& out_height) {
  int a = 0, b = 0;
  char x = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X') ||
      a <= 0 || b <= 0 || a > 100000 || b > 100000)
    return false;
  out_width = a;
  out_height = b;
  return true;
}

}  // namespace avatarmap::cli
