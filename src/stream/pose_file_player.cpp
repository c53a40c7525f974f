// include/avatarmap/stream/pose_file_player.hpp.
#include "avatarmap/stream/pose_file_player.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "avatarmap/io/pose_file.hpp"

namespace avatarmap {

struct pose_file_player::impl {
  std::string path;
  long frames = 0;
  double first_t = 0, last_t = 0, fps = 30;
  std::thread thread;
  std::mutex m;
  std::condition_variable wake;
  bool stopping = false;
  status error;
};

pose_file_player::pose_file_player() : impl_(std::make_unique<impl>()) {}
pose_file_player::~pose_file_player() { stop(); }

status pose_file_player::open(const std::string& path) {
  pose_reader reader;
  if (status st = reader.open(path); !st) return st;
  proxy_pose pose;
  long n = 0;
  for (;;) {
    const read_result r = reader.next(pose);
    if (r == read_result::end) break;
    if (r == read_result::error) return status::error(reader.error());
    if (n == 0) impl_->first_t = pose.t;
    impl_->last_t = pose.t;
    ++n;
  }
  if (n == 0) return status::error(path + ": holds no pose (nothing to play)");
  impl_->path = path;
  impl_->frames = n;
  if (reader.header().fps > 0) impl_->fps = reader.header().fps;
  return {};
}

long pose_file_player::frames() const { return impl_->frames; }
double pose_file_player::duration() const { return impl_->last_t - impl_->first_t; }

void pose_file_player::start(std::function<void(const proxy_pose&)> sink) {
  impl& s = *impl_;
  s.thread = std::thread([&s, sink = std::move(sink)] {
    using clock = std::chrono::steady_clock;
    const double step = 1.0 / s.fps;
    proxy_pose pose;
    std::unique_lock<std::mutex> lock(s.m);
    while (!s.stopping) {
      pose_reader reader;
      status st = reader.open(s.path);
      const auto loop_start = clock::now();
      double offset = 0;  // seconds into this loop of the pose read last
      double previous_t = 0;
      bool first = true;
      for (;;) {
        const read_result r = reader.next(pose);
        if (r == read_result::end) break;
        if (r == read_result::error) {
          st = status::error(reader.error());
          break;
        }
        if (first) {
          offset = 0;
          first = false;
        } else {
          offset += pose.t > previous_t ? pose.t - previous_t : step;
        }
        previous_t = pose.t;
        const auto due = loop_start + std::chrono::duration_cast<clock::duration>(
                                          std::chrono::duration<double>(offset));
        if (s.wake.wait_until(lock, due, [&] { return s.stopping; })) return;
        lock.unlock();
        sink(pose);
        lock.lock();
      }
      if (!st.ok() || first) {
        s.error = st.ok() ? status::error(s.path + ": holds no pose any more") : st;
        return;
      }
      const auto next_loop = loop_start + std::chrono::duration_cast<clock::duration>(
                                              std::chrono::duration<double>(offset + step));
      if (s.wake.wait_until(lock, next_loop, [&] { return s.stopping; })) return;
    }
  });
}

void pose_file_player::stop() {
  impl& s = *impl_;
  {
    std::lock_guard<std::mutex> lock(s.m);
    s.stopping = true;
  }
  s.wake.notify_all();
  if (s.thread.joinable()) s.thread.join();
}

status pose_file_player::error() const {
  std::lock_guard<std::mutex> lock(impl_->m);
  return impl_->error;
}

}  // namespace avatarmap
