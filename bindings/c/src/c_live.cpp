// The C API's live handle (avm_live_*): the library's live_session — the caller's camera thread
// pushes images, the session's worker processes the newest, any thread samples the pose.
#include <array>
#include <cmath>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "avatarmap/avatarmap.h"
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "c_capture_options.hpp"
#include "c_frames.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

// The error slot of a live handle is written by push and read by any thread: a mutex guards
// it, and avm_live_last_error copies it out.
struct avm_live {
  std::unique_ptr<am::live_session> session;
  mutable std::mutex error_m;
  char push_error[k_error_capacity] = "";
  // Pushes from several threads are serialised: `buffer` is the pushing thread's scratch.
  std::mutex push_m;
  char buffer[k_error_capacity] = "";

  avm_status push_failed(avm_status code, const char* msg) noexcept {
    std::lock_guard<std::mutex> lock(error_m);
    copy_message(push_error, sizeof push_error, msg);
    return code;
  }
};

namespace {

// The live handles alive now, each with the number of calls in flight on it. Every call
// enters through live_call: a handle that avm_live_destroy has taken out fails with
// AVM_ERROR_INVALID_ARGUMENT instead of touching freed memory, and destroy waits until the
// calls already in flight on other threads have returned. (An address reused by a new handle
// cannot be told from the old one: a call after destroy stays a caller error.)
struct live_registry {
  std::mutex m;
  std::condition_variable idle;
  std::unordered_map<const avm_live*, int> in_flight;
};
live_registry& registry() {
  static live_registry* r = new live_registry();  // never destroyed: usable at exit
  return *r;
}

class live_call {
 public:
  explicit live_call(const avm_live* live) noexcept : live_(live) {
    if (live == nullptr) return;
    live_registry& r = registry();
    std::lock_guard<std::mutex> lock(r.m);
    const auto it = r.in_flight.find(live);
    if (it == r.in_flight.end()) return;
    ++it->second;
    entered_ = true;
  }
  ~live_call() {
    if (!entered_) return;
    live_registry& r = registry();
    bool idle = false;
    {
      std::lock_guard<std::mutex> lock(r.m);
      // Still registered: destroy takes a handle out only once its count is zero.
      idle = --r.in_flight.find(live_)->second == 0;
    }
    if (idle) r.idle.notify_all();  // only destroy waits, and only for zero
  }
  live_call(const live_call&) = delete;
  live_call& operator=(const live_call&) = delete;
  /// Whether the handle is alive (registered and not being destroyed).
  bool ok() const noexcept { return entered_; }

 private:
  const avm_live* live_;
  bool entered_ = false;
};

avm_status rest_pose(double t, avm_pose* out) noexcept {
  am::proxy_pose rest;
  rest.set_rest();
  rest.t = t;
  to_c_pose(rest, *out);
  return AVM_ERROR_END_OF_FILE;
}
}  // namespace

extern "C" {

AVATARMAP_C_API avm_status avm_live_create(const avm_estimator_options* options,
                                           const avm_solver_options* solver_options,
                                           avm_live** out) {
  set_create_error("");
  if (out == nullptr) {
    set_create_error("avm_live_create: out is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  return guard("avm_live_create", to_create_error, [&]() -> avm_status {
    am::live_session_options lo;
    double extrapolation = 0.0;
    std::string msg;
    const avm_status code =
        read_capture_options(options, solver_options, lo.pipeline, extrapolation, msg);
    if (code != AVM_OK) return to_create_error(code, msg.c_str());
    lo.pipeline.resampler.max_extrapolation_seconds = extrapolation;
    std::unique_ptr<avm_live> l(new avm_live());
    const am::status st = am::live_session::create(lo, l->session);
    if (!st.ok()) return to_create_error(avm_code(st), st.message().c_str());
    {
      live_registry& r = registry();
      std::lock_guard<std::mutex> lock(r.m);
      r.in_flight.emplace(l.get(), 0);
    }
    *out = l.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_live_destroy(avm_live* live) {
  if (live == nullptr) return;
  guard_value(0, [&] {
    {
      // Taken out first (new calls fail), then freed once the calls in flight have returned.
      live_registry& r = registry();
      std::unique_lock<std::mutex> lock(r.m);
      const auto it = r.in_flight.find(live);
      if (it == r.in_flight.end()) return 0;  // destroyed already, or not a live handle
      r.idle.wait(lock, [&] { return it->second == 0; });
      r.in_flight.erase(it);
    }
    delete live;
    return 0;
  });
}

AVATARMAP_C_API avm_status avm_live_push(avm_live* live, const avm_image* image, double t) {
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  auto report = [live](avm_status code, const char* msg) noexcept {
    return live->push_failed(code, msg);
  };
  return guard("avm_live_push", report, [&]() -> avm_status {
    if (image == nullptr) return report(AVM_ERROR_INVALID_ARGUMENT, "avm_live_push: image is NULL");
    if (!std::isfinite(t))
      return report(AVM_ERROR_INVALID_ARGUMENT, "avm_live_push: t must be finite");
    std::lock_guard<std::mutex> push_lock(live->push_m);
    am::image_view view;
    if (const char* bad = to_image_view(*image, view, live->buffer, sizeof live->buffer))
      return report(AVM_ERROR_INVALID_ARGUMENT, bad);
    const am::status st = live->session->push(view, t);
    if (!st.ok()) return report(avm_code(st), st.message().c_str());
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_live_sample(const avm_live* live, double t, avm_pose* out_pose) {
  if (live == nullptr || out_pose == nullptr || !std::isfinite(t))
    return AVM_ERROR_INVALID_ARGUMENT;
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_live_sample", silently, [&]() -> avm_status {
    am::proxy_pose p;
    if (!live->session->sample(t, p)) return rest_pose(t, out_pose);
    to_c_pose(p, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_live_latest(const avm_live* live, avm_pose* out_pose) {
  if (live == nullptr || out_pose == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_live_latest", silently, [&]() -> avm_status {
    am::proxy_pose p;
    if (!live->session->latest(p)) return rest_pose(0.0, out_pose);
    to_c_pose(p, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_live_people(const avm_live* live, avm_live_person* out_people,
                                           int32_t capacity, int32_t* out_count) {
  if (live == nullptr || out_count == nullptr || capacity < 0 ||
      (out_people == nullptr && capacity > 0))
    return AVM_ERROR_INVALID_ARGUMENT;
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_live_people", silently, [&]() -> avm_status {
    std::array<am::live_person, am::k_max_people> held;
    const int n = live->session->people(held.data(), am::k_max_people);
    for (int i = 0; i < n && i < capacity; ++i)
      out_people[i] = {held[i].id, held[i].slot, held[i].seen_t};
    *out_count = n;
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_live_sample_person(const avm_live* live, int32_t id, double t,
                                                  avm_pose* out_pose) {
  if (live == nullptr || out_pose == nullptr || !std::isfinite(t))
    return AVM_ERROR_INVALID_ARGUMENT;
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_live_sample_person", silently, [&]() -> avm_status {
    am::proxy_pose p;
    if (!live->session->sample_person(id, t, p)) return rest_pose(t, out_pose);
    to_c_pose(p, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_live_get_stats(const avm_live* live, avm_live_stats* out_stats) {
  if (live == nullptr || out_stats == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  const live_call call(live);
  if (!call.ok()) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_live_get_stats", silently, [&]() -> avm_status {
    const am::live_session_stats s = live->session->stats();
    out_stats->pushed = s.pushed;
    out_stats->processed = s.processed;
    out_stats->dropped = s.dropped;
    out_stats->failed = s.failed;
    out_stats->latency_p50_ms = s.latency_p50_ms;
    out_stats->latency_p95_ms = s.latency_p95_ms;
    out_stats->latency_max_ms = s.latency_max_ms;
    out_stats->newest_t = s.newest_t;
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_live_last_error(const avm_live* live, char* buffer,
                                                size_t buffer_size) {
  return guard_value<const char*>(buffer, [&]() -> const char* {
    copy_message(buffer, buffer_size, "");
    if (live == nullptr) return buffer;
    const live_call call(live);
    if (!call.ok()) {
      copy_message(buffer, buffer_size, "avm_live: the handle was destroyed (or never created)");
      return buffer;
    }
    const am::status worker = live->session->last_error();
    if (!worker.ok()) {
      copy_message(buffer, buffer_size, worker.message().c_str());
      return buffer;
    }
    std::lock_guard<std::mutex> lock(live->error_m);
    copy_message(buffer, buffer_size, live->push_error);
    return buffer;
  });
}

}  // extern "C"
