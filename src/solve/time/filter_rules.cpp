#include "avatarmap/time/filter_rules.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace avatarmap {

namespace {

status check_one_euro(const char* name, const one_euro_params& p) {
  if (!(std::isfinite(p.min_cutoff) && p.min_cutoff > 0.f))
    return status::error(std::string("filter.") + name + ".min_cutoff must be finite and > 0");
  if (!(std::isfinite(p.beta) && p.beta >= 0.f))
    return status::error(std::string("filter.") + name + ".beta must be finite and >= 0");
  if (!(std::isfinite(p.d_cutoff) && p.d_cutoff > 0.f))
    return status::error(std::string("filter.") + name + ".d_cutoff must be finite and > 0");
  return {};
}

}  // namespace

status pose_stream_filters::validate() const {
  status st = check_one_euro("rotation", filter.rotation);
  if (st.ok()) st = check_one_euro("position", filter.position);
  if (st.ok()) st = check_one_euro("expression", filter.expression);
  if (!st.ok()) return st;
  if (filter_mode != pose_filter_mode::offline && filter_mode != pose_filter_mode::live &&
      filter_mode != pose_filter_mode::none)
    return status::error("filter_mode must be offline, live or none");
  if (status st2 = offline.validate(); !st2.ok()) return st2;
  return foot_contacts.validate();
}

status check_smoothing(double value, const std::string& name) {
  offline_smoother_options o;
  // A double that does not fit a float is out of range whatever the rule says.
  if (std::isfinite(value) && std::fabs(value) <= 1e30) {
    o.strength = static_cast<float>(value);
    if (o.validate().ok()) return {};
  }
  // The bound rounded down, so that the range printed is inside the one accepted.
  char bound[32];
  std::snprintf(bound, sizeof bound, "%.2f", std::floor(double(k_max_smoothing) * 100.0) / 100.0);
  return status::error(name + " must be finite and in [0, " + bound + "] (1 = default)");
}

}  // namespace avatarmap
