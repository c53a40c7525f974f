// The "onnx" estimator backend (AVATARMAP_HAVE_ONNX): the body part for now (pose_pipeline);
// hands and face are not estimated yet.
#pragma once

#include <memory>

#include "avatarmap/capture/estimator.hpp"

namespace avatarmap {

/// Creates the backend: options.source is the folder of converted models (pose_detection.onnx,
/// pose_landmark_full.onnx), options.threads the ORT intra-op threads.
status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out);

}  // namespace avatarmap
