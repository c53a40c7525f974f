#include "avatarmap/live/live_session.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/time/latency_stats.hpp"

namespace avatarmap {

namespace {

using clock_type = std::chrono::steady_clock;

// An image copied out of the caller's memory, rows packed.
struct image_copy {
  std::vector<std::uint8_t> pixels;
  image_view view{};
  double t = 0.0;
  long index = 0;
  clock_type::time_point pushed{};

  void copy_from(const image_view& v, double time) {
    const size_t row = static_cast<size_t>(v.width) * image_bytes_per_pixel(v.format);
    const size_t need = row * static_cast<size_t>(v.height);
    if (pixels.size() < need) pixels.resize(need);  // the first image, or a larger one
    for (int y = 0; y < v.height; ++y)
      std::memcpy(pixels.data() + row * y, v.data + static_cast<size_t>(v.stride_bytes) * y, row);
    view = {pixels.data(), v.width, v.height, static_cast<int>(row), v.format};
    t = time;
    pushed = clock_type::now();
  }
  void swap(image_copy& o) noexcept {
    pixels.swap(o.pixels);
    std::swap(view, o.view);
    std::swap(t, o.t);
    std::swap(index, o.index);
    std::swap(pushed, o.pushed);
  }
};

}  // namespace

struct live_session::impl {
  explicit impl(const live_session_options& o) : options(o), latencies(o.latency_samples) {}

  live_session_options options;
  std::unique_ptr<capture_pipeline> pipeline;

  // Images: `incoming` is the pushing thread's own (under `push_m`: pushes from several
  // threads are serialised); `waiting` is handed over under `m`; `work` is the worker's own.
  std::mutex push_m;
  image_copy incoming, waiting, work;
  mutable std::mutex m;
  std::condition_variable cv;                  // the worker waits on it
  mutable std::condition_variable stopped_cv;  // wait_stopped() waits on it
  bool has_waiting = false;
  bool finishing = false;  // finish(): no more pushes; the worker drains and stops
  bool halt = false;       // stop(): the worker stops at once
  bool worker_done = false;
  long pushed = 0, dropped = 0;

  // Results, under `out_m`: the pipeline's stream (solve and sample) and what it produced.
  mutable std::mutex out_m;
  proxy_pose newest;
  bool has_pose = false;
  long processed = 0, failed = 0, outputs = 0;
  latency_stats latencies;
  status error;
  // The stream's clock: the newest pose's capture time at the moment it reached the stream;
  // whether an output has carried it yet, and when its image was pushed.
  clock_type::time_point newest_at{};
  clock_type::time_point newest_pushed{};
  bool fresh = false;

  // The worker's scratch.
  landmark_frame frame;
  proxy_pose pose;
  people_poses people_scratch;  // several people
  std::thread worker;

  // The output thread's scratch (several people: one pose per held person).
  std::array<live_person, k_max_people> out_people{};
  std::array<proxy_pose, k_max_people> out_poses;
  // Per slot, the person the outputs were last handed (-1: none), and those gone this tick.
  std::array<int, k_max_people> handed{};
  std::array<live_person, k_max_people> gone{};

  bool several() const { return pipeline->max_people() > 1; }

  // The people held now, ascending by id (under out_m).
  int held_people(live_person* out, int capacity) const {
    std::array<live_person, k_max_people> all{};
    int n = 0;
    if (!several()) {
      if (has_pose) all[n++] = {0, 0, newest.t};
    } else {
      for (int k = 0; k < pipeline->max_people(); ++k)
        if (pipeline->slot_person(k) >= 0)
          all[n++] = {pipeline->slot_person(k), k, pipeline->slot_seen(k)};
      // Insertion by id (at most k_max_people).
      for (int i = 1; i < n; ++i)
        for (int j = i; j > 0 && all[j].id < all[j - 1].id; --j) std::swap(all[j], all[j - 1]);
    }
    for (int i = 0; i < n && i < capacity; ++i) out[i] = all[i];
    return n;
  }

  // The people handed to the outputs last time whose slot now holds nobody or someone else,
  // into gone[]; handed[] becomes out_people[0 .. n)'s (output thread, under out_m).
  int people_gone(int n) {
    std::array<int, k_max_people> now{};
    now.fill(-1);
    for (int i = 0; i < n; ++i)
      now[static_cast<std::size_t>(out_people[i].slot)] = out_people[i].id;
    int count = 0;
    for (std::size_t k = 0; k < handed.size(); ++k) {
      if (handed[k] >= 0 && handed[k] != now[k])
        gone[static_cast<std::size_t>(count++)] = {handed[k], static_cast<int>(k), 0.0};
      handed[k] = now[k];
    }
    return count;
  }

  // The stream sampled for `person` (slot 0 with one person; under out_m).
  bool sample_slot(int slot, double t, proxy_pose& out) const {
    if (!has_pose) return false;
    if (!pipeline->stream(slot).sample(t, out)) return false;
    out.t = t;
    return true;
  }

  // The output thread and what stops it.
  std::thread output;
  std::mutex output_m;
  std::condition_variable output_cv;
  bool output_stop = false;

  void run_worker() {
    for (;;) {
      long dropped_so_far = 0;
      {
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return halt || has_waiting || finishing; });
        if (halt || !has_waiting) break;  // stopped, or finished and drained
        work.swap(waiting);
        has_waiting = false;
        dropped_so_far = dropped;
      }
      // Estimation outside any lock (it is the long part); solving under out_m, so that
      // sample() never sees the stream half updated.
      const status st = pipeline->estimate(work.view, work.t, frame);
      double ms = 0.0;
      {
        std::lock_guard<std::mutex> lock(out_m);
        if (!st.ok()) {
          ++failed;
          error = st;
        } else {
          bool solved = true;
          if (several()) {
            pipeline->solve_people(frame, people_scratch);
            solved = people_scratch.count > 0;
            pose = solved ? people_scratch.people[0].pose : newest;
          } else {
            pipeline->solve(frame, pose);
          }
          const clock_type::time_point now = clock_type::now();
          ms = std::chrono::duration<double, std::milli>(now - work.pushed).count();
          if (solved) {
            newest = pose;
            has_pose = true;
          }
          ++processed;
          latencies.add(ms);
          newest_at = now;
          newest_pushed = work.pushed;
          fresh = true;
        }
      }
      if (options.on_frame) {
        live_frame_report r;
        r.index = work.index;
        r.t = work.t;
        r.dropped_so_far = dropped_so_far;
        if (st.ok()) {
          r.frame = &frame;
          r.pose = &pose;
          r.timings = pipeline->last_timings();
          r.latency_ms = ms;
          if (several()) r.people = &people_scratch;
        } else {
          r.error = &st;
        }
        if (!options.on_frame(r)) break;
      }
    }
    {
      std::lock_guard<std::mutex> lock(m);
      worker_done = true;
      if (has_waiting) {  // stopped with an image waiting: dropped
        ++dropped;
        has_waiting = false;
      }
    }
    stopped_cv.notify_all();
  }

  void run_output() {
    const auto period = std::chrono::duration_cast<clock_type::duration>(
        std::chrono::duration<double>(1.0 / options.output_fps));
    auto next = clock_type::now();
    double last_t = -INFINITY;  // output times always increase (processing time varies)
    live_output_report r;
    handed.fill(-1);
    for (;;) {
      next += period;
      {
        // Waits for the next period on the condition, so that a stop is seen at once
        // whatever output_fps is.
        std::unique_lock<std::mutex> lock(output_m);
        if (output_cv.wait_until(lock, next, [&] { return output_stop; })) return;
      }
      int n = 0, n_gone = 0;
      {
        std::lock_guard<std::mutex> lock(out_m);
        if (!has_pose) continue;
        const double t = std::max(
            last_t + 1e-6,
            newest.t + std::chrono::duration<double>(clock_type::now() - newest_at).count());
        if (several()) {
          const int held = held_people(out_people.data(), k_max_people);
          for (int i = 0; i < held; ++i)
            if (sample_slot(out_people[i].slot, t, out_poses[n])) out_people[n++] = out_people[i];
          n_gone = people_gone(n);
        } else if (sample_slot(0, t, out_poses[0])) {
          out_people[0] = {-1, 0, t};
          n = 1;
        }
        if (n == 0 && n_gone == 0) continue;
        if (n > 0) {
          last_t = t;
          r.carries_new_frame = fresh;
          r.pushed_at = newest_pushed;
          fresh = false;
          ++outputs;
        }
      }
      for (int i = 0; i < n_gone; ++i)
        for (const auto& g : options.on_person_gone)
          if (g) g(gone[i].id, gone[i].slot);
      for (int i = 0; i < n; ++i) {
        r.person = out_people[i].id;
        r.slot = out_people[i].slot;
        for (const live_output& out : options.outputs)
          if (out) out(out_poses[i], r);
      }
    }
  }
};

live_session::live_session(std::unique_ptr<impl> p) : impl_(std::move(p)) {}

status live_session::create(const live_session_options& options,
                            std::unique_ptr<live_session>& out) {
  out.reset();
  if (options.latency_samples < 1)
    return status::error("live_session_options.latency_samples must be >= 1");
  if (!(std::isfinite(options.output_fps) && options.output_fps >= 0.0 &&
        options.output_fps <= k_max_fps))
    return status::error("live_session_options.output_fps must be 0 (no output thread) or in (0, " +
                         limit_text(k_max_fps) + "]");
  auto p = std::make_unique<impl>(options);
  if (status st = capture_pipeline::create(options.pipeline, p->pipeline); !st.ok()) return st;
  p->newest.set_rest();
  impl* raw = p.get();
  p->worker = std::thread([raw] { raw->run_worker(); });
  if (options.output_fps > 0.0) p->output = std::thread([raw] { raw->run_output(); });
  out.reset(new live_session(std::move(p)));
  return {};
}

live_session::~live_session() { stop(); }

void live_session::stop() {
  impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.m);
    s.halt = true;
  }
  s.cv.notify_all();
  if (s.worker.joinable()) s.worker.join();
  {
    std::lock_guard<std::mutex> lock(s.output_m);
    s.output_stop = true;
  }
  s.output_cv.notify_all();
  if (s.output.joinable()) s.output.join();
}

void live_session::finish() {
  {
    std::lock_guard<std::mutex> lock(impl_->m);
    impl_->finishing = true;
  }
  impl_->cv.notify_all();
}

bool live_session::stopped() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->worker_done;
}

void live_session::wait_stopped() const {
  std::unique_lock<std::mutex> lock(impl_->m);
  impl_->stopped_cv.wait(lock, [&] { return impl_->worker_done; });
}

bool live_session::wait_stopped_until(std::chrono::steady_clock::time_point deadline) const {
  std::unique_lock<std::mutex> lock(impl_->m);
  return impl_->stopped_cv.wait_until(lock, deadline, [&] { return impl_->worker_done; });
}

status live_session::push(const image_view& image, double t) {
  if (!std::isfinite(t)) return status::error("live_session::push: t must be finite");
  if (status st = check_image(image); !st.ok()) return st;
  impl& s = *impl_;
  std::lock_guard<std::mutex> push_lock(s.push_m);
  s.incoming.copy_from(image, t);
  {
    std::lock_guard<std::mutex> lock(s.m);
    if (s.halt || s.finishing || s.worker_done)
      return status::error("live_session::push: the session has stopped");
    if (s.has_waiting) ++s.dropped;
    s.incoming.index = s.pushed;
    s.waiting.swap(s.incoming);
    s.has_waiting = true;
    ++s.pushed;
  }
  s.cv.notify_one();
  return {};
}

bool live_session::sample(double t, proxy_pose& out) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  live_person first;
  if (impl_->held_people(&first, 1) == 0) return false;
  return impl_->sample_slot(first.slot, t, out);
}

bool live_session::sample_person(int id, double t, proxy_pose& out) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  std::array<live_person, k_max_people> held;
  const int n = impl_->held_people(held.data(), k_max_people);
  for (int i = 0; i < n; ++i)
    if (held[i].id == id) return impl_->sample_slot(held[i].slot, t, out);
  return false;
}

int live_session::people(live_person* out, int capacity) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  return impl_->held_people(out, capacity);
}

bool live_session::latest(proxy_pose& out) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  if (!impl_->has_pose) return false;
  out = impl_->newest;
  return true;
}

live_session_stats live_session::stats() const {
  live_session_stats s;
  {
    std::lock_guard<std::mutex> lock(impl_->m);
    s.pushed = impl_->pushed;
    s.dropped = impl_->dropped;
  }
  std::unique_ptr<latency_stats> kept;
  {
    std::lock_guard<std::mutex> lock(impl_->out_m);
    s.processed = impl_->processed;
    s.failed = impl_->failed;
    s.outputs = impl_->outputs;
    s.newest_t = impl_->has_pose ? impl_->newest.t : 0.0;
    kept = std::make_unique<latency_stats>(impl_->latencies);  // sorted outside the lock
  }
  const latency_summary l = kept->summary();
  s.latency_mean_ms = l.mean_ms;
  s.latency_p50_ms = l.p50_ms;
  s.latency_p95_ms = l.p95_ms;
  s.latency_max_ms = l.max_ms;
  return s;
}

status live_session::last_error() const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  return impl_->error;
}

}  // namespace avatarmap
