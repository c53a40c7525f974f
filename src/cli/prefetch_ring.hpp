// The CLI's name for the library's producer/consumer ring (src/jobs/prefetch_ring.hpp), used
// by `capture` to decode video a few frames ahead of the estimator.
#pragma once

#include "jobs/prefetch_ring.hpp"

namespace avatarmap::cli {

using jobs_detail::prefetch_ring;

}  // namespace avatarmap::cli
