// Stage 1b of the solver: focal length from the body's image and world points. See
// solve_camera.hpp.
#include "solve/solve_camera.hpp"

#include <cmath>

#include "solve/solve_prepare.hpp"

namespace avatarmap::solve_detail {
namespace {

// Least confidence of a point used: the fit's own choice, not the solver's gate thresholds
// (which the offline job opens to 0): an occluded point's position is a guess.
constexpr float k_min_point_confidence = 0.5f;
// Fewest confident points for a fit (two equations each, four unknowns): a fit through a
// handful of points is dominated by their noise.
constexpr int k_min_points = 8;
// Plausible focal lengths, as a multiple of the image width: fields of view from ~19 to
// ~112 degrees. Estimates outside are dropped (a frame whose world and image points disagree).
constexpr double k_min_focal_per_width = 0.3;
constexpr double k_max_focal_per_width = 3.0;
// Nearest plausible camera (metres from the hips).
constexpr double k_min_depth = 0.2;
// Largest residual standard deviation (as a fraction of the image width) of a frame whose
// image and world points are one pinhole view. Exact or 3-D-noisy points fit to well under a
// pixel; independent noise of ~10 mm on image and world points at 1.5-4 m is ~0.3 % of the
// width; MediaPipe's own world points disagree with its image points by ~2 % (its world model
// is a separate regression, not a projection), so real video keeps the prior. On rendered
// mocap captured by our models a few frames per take came under 1 % and pulled the estimate
// 10-30 degrees off (docs/world-benchmark.md): 0.6 % keeps them out.
constexpr double k_max_residual_per_width = 0.006;
// Least residual standard deviation assumed (pixels): exact synthetic points would otherwise
// claim infinite information.
constexpr double k_min_residual_px = 0.5;
// The world points' lean searched: +-30 degrees, every 10 degrees, then refined to 2.5.
constexpr double k_lean_max_degrees = 30.0;
constexpr double k_lean_coarse_degrees = 10.0;

// Solves the 4x4 system a x = b in place (Gaussian elimination with partial pivoting);
// false when singular.
bool solve4(double a[4][4], double b[4], double x[4]) {
  int row[4] = {0, 1, 2, 3};
  for (int c = 0; c < 4; ++c) {
    int best = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(a[row[r]][c]) > std::fabs(a[row[best]][c])) best = r;
    std::swap(row[c], row[best]);
    const double p = a[row[c]][c];
    if (!(std::fabs(p) > 1e-12)) return false;
    for (int r = c + 1; r < 4; ++r) {
      const double k = a[row[r]][c] / p;
      for (int j = c; j < 4; ++j) a[row[r]][j] -= k * a[row[c]][j];
      b[row[r]] -= k * b[row[c]];
    }
  }
  for (int c = 3; c >= 0; --c) {
    double s = b[row[c]];
    for (int j = c + 1; j < 4; ++j) s -= a[row[c]][j] * x[j];
    x[c] = s / a[row[c]][c];
  }
  return true;
}

}  // namespace

namespace {

// The pinhole fit of one frame with the world points turned by `lean` radians about the
// camera's x axis (through the hips): the unknowns, the residual sum of squares, the normal
// matrix; false when too few points or singular.
struct pinhole_fit {
  double x[4] = {};
  double rss = 0.0;
  double n[4][4] = {};
  int m = 0;
};

bool fit_pinhole(const landmark_frame& in, float width, float height, double lean,
                 pinhole_fit& out) {
  // Normal equations of the unknowns (Tz, f, f Tx, f Ty), rows [du, -X, -1, 0] and
  // [dv, -Y, 0, -1] with right-hand sides -du Z and -dv Z, and the right-hand sides' sum of
  // squares (for the residual without a second pass: rss = y'y - x'A'y at the solution).
  const double c = std::cos(lean), s = std::sin(lean);
  double r[4] = {}, yy = 0.0;
  out = pinhole_fit{};
  for (int i = 0; i < k_pose_landmark_count; ++i) {
    const landmark& p = in.pose[i];
    const landmark& w = in.pose_world[i];
    if (std::min(landmark_confidence(p), landmark_confidence(w)) < k_min_point_confidence) continue;
    const double du = (double(p.x) - 0.5) * width, dv = (double(p.y) - 0.5) * height;
    const double wy = double(w.y) * c - double(w.z) * s, wz = double(w.y) * s + double(w.z) * c;
    const double eq[2][5] = {{du, -double(w.x), -1.0, 0.0, -du * wz},
                             {dv, -wy, 0.0, -1.0, -dv * wz}};
    for (const auto& q : eq) {
      for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) out.n[row][col] += q[row] * q[col];
        r[row] += q[row] * q[4];
      }
      yy += q[4] * q[4];
      ++out.m;
    }
  }
  if (out.m < 2 * k_min_points) return false;
  double a[4][4], b[4];
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) a[i][j] = out.n[i][j];
    b[i] = r[i];
  }
  if (!solve4(a, b, out.x)) return false;
  out.rss =
      std::max(0.0, yy - (out.x[0] * r[0] + out.x[1] * r[1] + out.x[2] * r[2] + out.x[3] * r[3]));
  return true;
}

}  // namespace

focal_evidence estimate_focal(const landmark_frame& in, float width, float height) {
  focal_evidence e;
  if (!in.has(frame_part::pose) || !in.has(frame_part::pose_world) || !(width > 0.f) ||
      !(height > 0.f))
    return e;
  // BlazePose's world points lean toward the camera (docs/solver.md): a lean the fit does not
  // model biases the focal length (fields of view of ~100 degrees measured where the truth
  // was 60). The lean is searched for: the fit with the least residual over world points
  // turned about the camera's x axis (11 fits, coarse to fine).
  pinhole_fit best, fit;
  double best_lean = 0.0;
  auto consider = [&](double degrees) {
    if (!fit_pinhole(in, width, height, degrees * 3.14159265358979 / 180.0, fit)) return false;
    if (best.m == 0 || fit.rss < best.rss) {
      best = fit;
      best_lean = degrees;
    }
    return true;
  };
  // Coarse (every k_lean_coarse_degrees over +-k_lean_max_degrees), then two halvings.
  for (double a = -k_lean_max_degrees; a <= k_lean_max_degrees + 1e-9; a += k_lean_coarse_degrees)
    if (!consider(a)) return e;
  for (double step = 0.5 * k_lean_coarse_degrees; step >= 0.25 * k_lean_coarse_degrees;
       step *= 0.5) {
    const double centre = best_lean;
    consider(centre - step);
    consider(centre + step);
  }
  const double tz = best.x[0], f = best.x[1];
  if (!(tz > k_min_depth) || !(f > k_min_focal_per_width * width) ||
      !(f < k_max_focal_per_width * width))
    return e;
  // Residual variance, in pixels^2 at the hips' depth (the equations are in pixels x metres).
  const double residual2 = best.rss / double(best.m - 5) / (tz * tz);
  const double max_residual = k_max_residual_per_width * width;
  if (!(residual2 <= max_residual * max_residual)) return e;
  const double sigma2 = std::max(residual2, k_min_residual_px * k_min_residual_px);
  // Variance of f: sigma^2 (N^-1)_ff, with N scaled to pixels (divide the equations by Tz).
  double unit[4] = {0.0, 1.0, 0.0, 0.0}, col[4], a[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) a[i][j] = best.n[i][j] / (tz * tz);
  if (!solve4(a, unit, col) || !(col[1] > 0.0)) return e;
  e.focal = f;
  e.information = 1.0 / (sigma2 * col[1]);
  e.lean = best_lean * 3.14159265358979 / 180.0;
  return e;
}

}  // namespace avatarmap::solve_detail
