// people_tracker: the ids and the detector schedule of a several-people capture
// (people_tracker.hpp has the rule).
#include "avatarmap/capture/people_tracker.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

namespace {
// Two tracks on one body: the one whose shoulder centre moved more than this many torso
// lengths further than the other's on the last frame jumped onto it.
constexpr float k_merge_jump_margin = 0.3f;
// The recent moves fade with this time constant; a frame whose own move is below
// k_steady_move torso lengths is steady (its motion is what a lost id waits with).
constexpr double k_jump_fade_seconds = 0.3;
constexpr float k_steady_move = 0.15f;
// The jump rule applies between tracks started at least this long ago.
constexpr double k_settled_seconds = 0.3;
// A track slid onto another person: its shoulder centre moved at least k_slide_min_move torso
// lengths at k_slide_speed torso lengths per second or faster (a person's shoulders do not:
// about 3 m/s), and at least half of that move brought it nearer another track's shoulder
// centre.
constexpr float k_slide_min_move = 0.5f;
constexpr float k_slide_speed = 6.0f;
// A region's side in pixels (regions are squares in pixels; the larger side otherwise).
float side_px(const normalized_rect& r, int w, int h) {
  return std::max(r.width * static_cast<float>(w), r.height * static_cast<float>(h));
}
}  // namespace

people_tracker::people_tracker(const people_tracker_options& options) : options_(options) {
  options_.max_people = std::clamp(options_.max_people, 1, k_max_people);
  reset();
}

void people_tracker::reset() {
  active_count_ = 0;
  for (motion& m : lost_) m.id = -1;
  next_id_ = 0;
  last_detection_t_ = 0.0;
  detected_once_ = false;
  lost_since_detection_ = false;
}

bool people_tracker::wants_detection(double t) const {
  if (active_count_ == 0 || !detected_once_) return true;
  if (active_count_ >= options_.max_people) return false;
  if (lost_since_detection_ || !(t >= last_detection_t_) ||
      t - last_detection_t_ >= options_.redetect_seconds)
    return true;
  // A person lost a moment ago may come out from behind someone: look on every frame while
  // its id waits.
  for (const motion& m : lost_)
    if (m.id >= 0 && t - m.t <= options_.keep_lost_seconds) return true;
  return false;
}

int people_tracker::index_of_slot(int slot) const {
  for (int i = 0; i < active_count_; ++i)
    if (tracks_[i].slot == slot) return i;
  return -1;
}

int people_tracker::take_id(double t, float x, float y, float size) {
  int best = -1;
  float best_d = INFINITY;
  for (int i = 0; i < k_lost_capacity; ++i) {
    const motion& m = lost_[i];
    if (m.id < 0 || !(t - m.t <= options_.keep_lost_seconds) || !(m.size > 0.f)) continue;
    const float dt = static_cast<float>(std::max(0.0, t - m.t));
    const float px = m.x + m.vx * dt, py = m.y + m.vy * dt;
    const float d = std::hypot(x - px, y - py);
    const float ratio = size / m.size;
    if (d <= options_.reid_max_offset * m.size && ratio <= options_.reid_max_scale &&
        ratio >= 1.f / options_.reid_max_scale && d < best_d) {
      best = i;
      best_d = d;
    }
  }
  if (best >= 0) {
    const int id = lost_[best].id;
    lost_[best].id = -1;
    return id;
  }
  // A new id, never one in use (after k_max_person_id the count wraps).
  for (;;) {
    const int id = next_id_;
    next_id_ = next_id_ >= k_max_person_id ? 0 : next_id_ + 1;
    bool used = false;
    for (int i = 0; i < active_count_; ++i) used = used || tracks_[i].id == id;
    for (const motion& m : lost_) used = used || m.id == id;
    if (!used) return id;
  }
}

void people_tracker::on_detections(double t, const normalized_rect* regions, const float* anchors,
                                   int count, int image_width, int image_height) {
  last_detection_t_ = t;
  detected_once_ = true;
  lost_since_detection_ = false;
  for (int i = 0; i < active_count_; ++i) tracks_[i].is_new = false;
  count = std::clamp(count, 0, k_max_people);
  const float fw = static_cast<float>(image_width), fh = static_cast<float>(image_height);
  // The boxes nobody tracks, largest first (stable: equal sizes keep the detector's order).
  std::array<int, k_max_people> order{};
  int n = 0;
  for (int b = 0; b < count; ++b) {
    const float sx = anchors[4 * b + 2] * fw, sy = anchors[4 * b + 3] * fh;
    bool tracked = false;
    for (int i = 0; i < active_count_ && !tracked; ++i) {
      const body_points& p = body_[tracks_[i].slot];
      if (!(p.torso > 0.f)) continue;  // started this frame: no landmarks yet
      const float tx = 0.5f * (p.xy[2] + p.xy[4]), ty = 0.5f * (p.xy[3] + p.xy[5]);
      tracked = std::hypot(sx - tx, sy - ty) <= options_.same_person_offset * p.torso;
    }
    if (!tracked) order[n++] = b;
  }
  // Insertion sorts here and below: stable, and std::stable_sort allocates a buffer.
  for (int i = 1; i < n; ++i) {
    const int v = order[i];
    const float sv = side_px(regions[v], image_width, image_height);
    int j = i;
    for (; j > 0 && side_px(regions[order[j - 1]], image_width, image_height) < sv; --j)
      order[j] = order[j - 1];
    order[j] = v;
  }
  for (int k = 0; k < n && active_count_ < options_.max_people; ++k) {
    const normalized_rect& r = regions[order[k]];
    int slot = 0;
    while (index_of_slot(slot) >= 0) ++slot;
    const float x = r.x_center * fw;
    const float y = r.y_center * fh;
    const float size = side_px(r, image_width, image_height);
    const int id = take_id(t, x, y, size);
    track& tr = tracks_[active_count_++];
    tr.id = id;
    tr.slot = slot;
    tr.is_new = true;
    tr.start_region = r;
    body_[slot] = body_points{};
    body_[slot].start = t;
    motion_[slot] = motion{tr.id, t, x, y, size, 0.f, 0.f, false};
    steady_[slot] = motion_[slot];
  }
  for (int i = 1; i < active_count_; ++i) {
    const track v = tracks_[i];
    int j = i;
    for (; j > 0 && tracks_[j - 1].id > v.id; --j) tracks_[j] = tracks_[j - 1];
    tracks_[j] = v;
  }
}

void people_tracker::on_found(int slot, double t, const normalized_rect& used,
                              const normalized_rect& /*next*/, const landmark* pose,
                              int image_width, int image_height) {
  const int index = index_of_slot(slot);
  if (index < 0) return;
  tracks_[index].is_new = false;  // started: its slots now carry it
  motion& m = motion_[slot];
  const float x = used.x_center * static_cast<float>(image_width);
  const float y = used.y_center * static_cast<float>(image_height);
  const double dt = t - m.t;
  if (dt > 0.0) {
    const float vx = static_cast<float>((x - m.x) / dt), vy = static_cast<float>((y - m.y) / dt);
    // A short average: one frame's jitter should not throw the prediction far.
    m.vx = m.has_velocity ? 0.5f * (m.vx + vx) : vx;
    m.vy = m.has_velocity ? 0.5f * (m.vy + vy) : vy;
    m.has_velocity = true;
  }
  m.t = t;
  m.x = x;
  m.y = y;
  m.size = side_px(used, image_width, image_height);
  body_points& b = body_[slot];
  // The shoulder centre before this frame (none for a new track: torso 0).
  const bool had = b.torso > 0.f;
  const float sx0 = 0.5f * (b.xy[2] + b.xy[4]), sy0 = 0.5f * (b.xy[3] + b.xy[5]);
  constexpr int k_points[5] = {0, 11, 12, 23, 24};  // nose, shoulders, hips
  for (int k = 0; k < 5; ++k) {
    b.xy[2 * k] = pose[k_points[k]].x * static_cast<float>(image_width);
    b.xy[2 * k + 1] = pose[k_points[k]].y * static_cast<float>(image_height);
  }
  const float dx = 0.5f * (b.xy[2] + b.xy[4] - b.xy[6] - b.xy[8]);
  const float dy = 0.5f * (b.xy[3] + b.xy[5] - b.xy[7] - b.xy[9]);
  b.torso = std::hypot(dx, dy);
  if (!std::isfinite(b.torso)) b.torso = 0.f;
  float move = 0.f;
  if (had && b.torso > 0.f) {
    move = std::hypot(0.5f * (b.xy[2] + b.xy[4]) - sx0, 0.5f * (b.xy[3] + b.xy[5]) - sy0) / b.torso;
    if (!std::isfinite(move)) move = 0.f;
  }
  const double since = had ? t - b.t : 0.0;
  const float fade = since > 0.0 ? static_cast<float>(std::exp(-since / k_jump_fade_seconds)) : 0.f;
  b.jump = (had ? fade * b.jump : 0.f) + move;
  b.t = t;
  // Slid onto another person (its own hidden: the model follows the body in front)?
  b.slid = false;
  if (move >= k_slide_min_move && since > 0.0 && move / since >= k_slide_speed) {
    const float sx1 = 0.5f * (b.xy[2] + b.xy[4]), sy1 = 0.5f * (b.xy[3] + b.xy[5]);
    for (int i = 0; i < active_count_ && !b.slid; ++i) {
      const body_points& o = body_[tracks_[i].slot];
      if (tracks_[i].slot == slot || !(o.torso > 0.f)) continue;
      const float ox = 0.5f * (o.xy[2] + o.xy[4]), oy = 0.5f * (o.xy[3] + o.xy[5]);
      const float nearer = std::hypot(sx0 - ox, sy0 - oy) - std::hypot(sx1 - ox, sy1 - oy);
      b.slid = nearer >= 0.5f * move * b.torso;
    }
  }
  if (!had || move < k_steady_move) steady_[slot] = m;
}

void people_tracker::remove(int index, double t, bool keep_id, bool before_last) {
  const int slot = tracks_[index].slot;
  if (keep_id) {
    // Into the lost list: a free entry, else the one seen longest ago.
    int at = 0;
    for (int i = 0; i < k_lost_capacity; ++i) {
      if (lost_[i].id < 0) {
        at = i;
        break;
      }
      if (lost_[i].t < lost_[at].t) at = i;
    }
    lost_[at] = before_last ? steady_[slot] : motion_[slot];
    lost_[at].id = tracks_[index].id;
    if (!(lost_[at].t <= t)) lost_[at].t = t;
  }
  for (int i = index; i + 1 < active_count_; ++i) tracks_[i] = tracks_[i + 1];
  --active_count_;
}

void people_tracker::on_lost(int slot, double t) {
  const int i = index_of_slot(slot);
  if (i < 0) return;
  remove(i, t, true);
  lost_since_detection_ = true;
}

int people_tracker::resolve_merges(double t, int* out_slots) {
  int n = 0;
  // Tracks that slid onto another person this frame end first (as lost, waiting with the
  // motion of their last steady frame: the person may come back from behind).
  for (int i = 0; i < active_count_;) {
    body_points& b = body_[tracks_[i].slot];
    if (!(b.slid && b.t == t)) {
      ++i;
      continue;
    }
    b.slid = false;
    out_slots[n++] = tracks_[i].slot;
    remove(i, t, true, true);
    lost_since_detection_ = true;
  }
  for (int i = 0; i < active_count_; ++i) {
    for (int j = i + 1; j < active_count_;) {
      const body_points& a = body_[tracks_[i].slot];
      const body_points& b = body_[tracks_[j].slot];
      float mean = 0.f;
      for (int k = 0; k < 5; ++k)
        mean += std::hypot(a.xy[2 * k] - b.xy[2 * k], a.xy[2 * k + 1] - b.xy[2 * k + 1]) / 5.f;
      const float torso = std::min(a.torso, b.torso);
      if (torso > 0.f && mean <= options_.merged_offset * torso) {
        // tracks_ ascend by id: j is the younger. The one that jumped onto the body ends.
        // Only between tracks both followed for a while: a track just started from a detector
        // box on a body another track follows is the extra one, whatever moved.
        const bool settled = t - a.start >= k_settled_seconds && t - b.start >= k_settled_seconds;
        const bool i_jumped = settled && a.jump > b.jump + k_merge_jump_margin;
        const bool j_jumped = settled && b.jump > a.jump + k_merge_jump_margin;
        const int end = i_jumped ? i : j;
        out_slots[n++] = tracks_[end].slot;
        remove(end, t, true, i_jumped || j_jumped);
        lost_since_detection_ = true;
        if (end == i) {  // tracks_[i] is now the next track: compare it afresh
          j = i + 1;
          continue;
        }
      } else {
        ++j;
      }
    }
  }
  return n;
}

}  // namespace avatarmap
