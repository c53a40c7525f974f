// avm_estimator_options and avm_image (avatarmap.h) read into the library's capture options and
// image view; shared by the estimator and live handles.
#pragma once

#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/capture/capture_pipeline.hpp"

namespace avatarmap::c_api {

/// The defaults, as avm_estimator_options_init() gives them.
avm_estimator_options default_estimator_options();

/// Reads caller options (either may be NULL = defaults) into `out`. On failure returns the
/// status (AVM_ERROR_INVALID_ARGUMENT; AVM_ERROR_UNSUPPORTED when this build has no ONNX
/// backend) and writes a message naming the field into `msg`.
avm_status read_capture_options(const avm_estimator_options* in,
                                const avm_solver_options* solver_in, capture_pipeline_options& out,
                                double& max_extrapolation_seconds, std::string& msg);

/// The C image as an image view; NULL when it passes check_image(), else a message (static
/// for the NULL and format cases, else written into `buffer`).
const char* to_image_view(const avm_image& in, image_view& out, char* buffer, size_t size);

}  // namespace avatarmap::c_api
