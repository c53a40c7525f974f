// Import of the TensorFlow.js pose-detection test recordings (tfjs-models, e.g.
// pose_squats.full.json + pose_squats_3d.full.json, or a hand recording) into a
// *.landmarks.jsonl file.
#pragma once

#include <string>

#include "avatarmap/core/status.hpp"

namespace avatarmap {

/// Converts a BlazePose recording in tfjs-models' test format to a landmarks file.
/// `image_json`: a JSON array of frames, each an array of 33 [x_px, y_px, z_px] image points
/// in pixels (z at the scale of x). `world_json`: the same number of frames of 33 [x, y, z]
/// world points in metres. Image points are normalised: x / image_width, y / image_height,
/// z / image_width; world points are copied; visibility and presence are 1; frame i gets
/// t = i / fps. The output has a header with image_size and fps and is written atomically.
/// Fails (with a message naming the file and frame) when a file cannot be read or parsed,
/// the frame counts differ, a frame does not have 33 points of 3 numbers, or
/// image_width/image_height/fps are not positive.
status import_tfjs_pose(const std::string& image_json, const std::string& world_json,
                        int image_width, int image_height, double fps,
                        const std::string& out_landmarks_path);

/// The same for a hand recording of tfjs-models' hand-pose-detection tests (e.g.
/// asl_hand.full.json + asl_hand_3d.full.json): frames of 21 points, written as the left or
/// the right hand (`left`; the files do not say which) with its world points (metres). The
/// errors are those of import_tfjs_pose, with 21 points per frame.
status import_tfjs_hand(const std::string& image_json, const std::string& world_json,
                        int image_width, int image_height, double fps, bool left,
                        const std::string& out_landmarks_path);

}  // namespace avatarmap
