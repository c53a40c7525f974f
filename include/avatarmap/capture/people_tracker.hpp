// Who is who when several people are captured (estimator_options::max_people > 1): the
// bookkeeping between the pose detector's boxes and the per-person tracks of the pipelines.
// Plain geometry, no models: the onnx estimator asks it when to run the detector, tells it
// what the detector and each person's landmarks found, and takes from it the ids.
//
// The rule (docs/capture-people.md):
// - The detector runs when nobody is tracked, on the frame after a track was lost, and every
//   redetect_seconds while fewer than max_people are tracked, on every frame while a lost id
//   waits (a person hidden a moment ago comes out from behind someone); with max_people
//   tracked it does not run (the cost grows with the people in view, not with max_people).
// - A detector box is a tracked person when its shoulder centre (the detector's keypoint 2)
//   lies within same_person_offset of that person's torso length (shoulder centre to hip
//   centre, pixels) from the person's shoulder centre (the mean of landmarks 11 and 12): the
//   track keeps its own region. (Region overlap does not tell people apart: a body cut by the
//   frame gets a region of twice the image, and such regions overlap for any neighbours.)
// - The other boxes, largest first, start tracks while fewer than max_people are tracked. Each
//   takes back the id of a person lost less than keep_lost_seconds ago whose box, moved on by
//   its last velocity, lies within reid_max_offset of its size from the new box's centre and
//   whose size is within a factor reid_max_scale; the nearest such. Otherwise a new id (ids
//   count up from 0; a still image's people get 0, 1, ... largest first).
// - Two tracks whose nose, shoulders and hips lie on average within merged_offset of the
//   smaller torso length of each other follow one body: the lower id (the person known
//   longer) keeps it, the other is ended as lost (its id may come back).
// - A track whose shoulder centre moves half a torso length or more in one frame, at 6 torso
//   lengths a second or faster (faster than shoulders move), and at least half of that toward
//   another track's shoulder centre has slid onto that person: its own person is hidden and
//   the model follows the body in front. It is ended as lost on that frame, before its
//   skeleton is given out (its id may come back).
//
// Spaces: regions in normalised image coordinates (image_crop.hpp); sizes and motion are
// measured in pixels of the image size given with each call; times in seconds.
// Memory: fixed arrays, nothing allocated. Not thread-safe.
#pragma once

#include <array>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// How long a lost person's id waits to be given back (seconds): the default of
/// people_tracker_options::keep_lost_seconds, and how long capture_pipeline keeps the person's
/// slot (k_person_hold_seconds).
inline constexpr double k_keep_lost_seconds = 1.0;

struct people_tracker_options {
  int max_people = 2;               // 1 .. k_max_people
  double redetect_seconds = 0.1;    // detector schedule while fewer than max_people tracked
  float same_person_offset = 0.5f;  // box to track shoulder centres / torso: the same person
  float merged_offset = 0.2f;       // mean key point distance / torso: one body
  double keep_lost_seconds =
      k_keep_lost_seconds;       // how long a lost person's id waits to be given back
  float reid_max_offset = 0.5f;  // centre distance / size allowed to take an id back
  float reid_max_scale = 1.5f;   // size ratio allowed to take an id back
};

class people_tracker {
 public:
  /// One tracked person: its id, the pipelines' slot holding its state, its region.
  struct track {
    int id = 0;
    int slot = 0;                  // 0 .. max_people - 1: the pipelines' person slot
    bool is_new = false;           // started by on_detections(), not found yet: seed its slots
    normalized_rect start_region;  // is_new: the detector's region to start from
  };

  explicit people_tracker(const people_tracker_options& options = {});
  /// Forgets every track, lost id and the id counter (a new take, or each still image).
  void reset();

  /// Whether the detector should run on the frame at time `t`.
  bool wants_detection(double t) const;
  /// The detector ran on the frame at `t` and found `count` regions (best first). Boxes that
  /// are tracked people are dropped; the others start tracks (largest first) while fewer than
  /// max_people are tracked, with their ids (see the rule above). New tracks come with
  /// is_new set.
  /// `anchors`: per region the detector's hip centre (keypoint 0) and shoulder centre
  /// (keypoint 2) as x0, y0, x2, y2 (normalised).
  void on_detections(double t, const normalized_rect* regions, const float* anchors, int count,
                     int image_width, int image_height);
  /// The tracked people, ascending by id (active_count() of them). A track found or lost
  /// must be reported with on_found() / on_lost() before the next on_detections().
  int active_count() const { return active_count_; }
  const track& active(int i) const { return tracks_[i]; }
  /// The landmarks of the track in slot `slot` were found on the frame at `t` in `used` (the
  /// region they ran on); `next` is the region tracked into the next frame.
  /// `pose`: the 33 body landmarks found (normalised).
  void on_found(int slot, double t, const normalized_rect& used, const normalized_rect& next,
                const landmark* pose, int image_width, int image_height);
  /// The track in slot `slot` lost its person at `t`: its id waits keep_lost_seconds.
  void on_lost(int slot, double t);
  /// Ends every track that slid onto another person on its last frame (the rule above; as
  /// lost, waiting with its motion from its last steady frame), then one of every two tracks
  /// that follow one body (merged_offset; as lost): between two
  /// tracks started at least 0.3 s ago the one that jumped onto it (its recent moves, in torso
  /// lengths and fading with a time constant of k_jump_fade_seconds, exceed the other's by
  /// k_merge_jump_margin: a track whose person is hidden slides onto the one in front), else the
  /// younger; a track ended for jumping waits with its motion from its last steady frame. Their
  /// slots into `out_slots` (room for max_people). Returns how many.
  int resolve_merges(double t, int* out_slots);

 private:
  struct motion {
    int id = -1;
    double t = 0.0;                      // when last seen
    float x = 0.f, y = 0.f, size = 0.f;  // box centre and side, pixels
    float vx = 0.f, vy = 0.f;            // pixels per second
    bool has_velocity = false;
  };
  int index_of_slot(int slot) const;
  void remove(int index, double t, bool keep_id, bool before_last = false);
  int take_id(double t, float x, float y, float size);

  people_tracker_options options_;
  std::array<track, k_max_people> tracks_{};
  std::array<motion, k_max_people> motion_{};  // per slot
  std::array<motion, k_max_people> steady_{};  // per slot: motion_ on its last steady frame
  // Per slot, pixels: nose, left and right shoulder, left and right hip (x, y each), and the
  // torso length (shoulder centre to hip centre; 0 before the first landmarks).
  struct body_points {
    std::array<float, 10> xy{};
    float torso = 0.f;
    float jump = 0.f;    // the shoulder centre's recent moves, torso lengths, fading
    bool slid = false;   // on its last frame it slid onto another person (resolve_merges)
    double t = 0.0;      // when found last
    double start = 0.0;  // when the track started
  };
  std::array<body_points, k_max_people> body_{};
  int active_count_ = 0;
  static constexpr int k_lost_capacity = 2 * k_max_people;
  std::array<motion, k_lost_capacity> lost_{};
  int next_id_ = 0;
  double last_detection_t_ = 0.0;
  bool detected_once_ = false;
  bool lost_since_detection_ = false;
};

}  // namespace avatarmap
