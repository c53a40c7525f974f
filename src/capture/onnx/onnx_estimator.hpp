// The "onnx" estimator backend (AVATARMAP_HAVE_ONNX): body, hands and face through
// pose_pipeline, hand_pipeline and face_pipeline.
#pragma once

#include <memory>

#include "avatarmap/capture/estimator.hpp"

namespace avatarmap {

/// Creates the backend: options.source is the folder of converted models, options.threads the
/// ORT intra-op threads of each model; the hand and face models are loaded only when
/// options.hands / options.face ask for them (estimate_args::hands/face are ignored
/// otherwise).
status create_onnx_estimator(const estimator_options& options, std::unique_ptr<estimator>& out);

}  // namespace avatarmap
