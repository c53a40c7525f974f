// overlay_job: clipped, thick Bresenham lines, discs and rectangle outlines on RGB8.
#include "avatarmap/capture/overlay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace avatarmap {

namespace {

constexpr int k_max_side = 65535;
constexpr int k_max_thickness = 64;

// The image as the rasteriser sees it. Every write goes through put(), which checks the
// bounds: clipping keeps the loops short, the check keeps the buffer safe whatever happens.
struct canvas {
  std::uint8_t* data;
  int width;
  int height;
  std::ptrdiff_t stride;

  void put(int x, int y, rgb8_color c) const {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::uint8_t* p = data + static_cast<std::ptrdiff_t>(y) * stride + 3 * x;
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
  }
  // Pixels x0..x1 (inclusive) of row y, clipped.
  void row(int x0, int x1, int y, rgb8_color c) const {
    if (y < 0 || y >= height) return;
    x0 = std::max(x0, 0);
    x1 = std::min(x1, width - 1);
    for (int x = x0; x <= x1; ++x) put(x, y, c);
  }
  // Pixels y0..y1 (inclusive) of column x, clipped.
  void column(int x, int y0, int y1, rgb8_color c) const {
    if (x < 0 || x >= width) return;
    y0 = std::max(y0, 0);
    y1 = std::min(y1, height - 1);
    for (int y = y0; y <= y1; ++y) put(x, y, c);
  }
};

rgb8_color dimmed(rgb8_color c) {
  return {static_cast<std::uint8_t>(c.r / 2), static_cast<std::uint8_t>(c.g / 2),
          static_cast<std::uint8_t>(c.b / 2)};
}

// Liang-Barsky: clips the segment (x0, y0)-(x1, y1) to [xmin, xmax] x [ymin, ymax]. False
// when nothing of it is inside. Inputs are finite.
bool clip_segment(double& x0, double& y0, double& x1, double& y1, double xmin, double ymin,
                  double xmax, double ymax) {
  const double dx = x1 - x0;
  const double dy = y1 - y0;
  double t0 = 0.0;
  double t1 = 1.0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x0 - xmin, xmax - x0, y0 - ymin, ymax - y0};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;  // parallel to this edge and outside it
      continue;
    }
    const double r = q[i] / p[i];
    if (p[i] < 0.0) {
      if (r > t1) return false;
      t0 = std::max(t0, r);
    } else {
      if (r < t0) return false;
      t1 = std::min(t1, r);
    }
  }
  // The differences of huge coordinates lose the small ones: clamp what rounding pushed out.
  const double nx0 = std::clamp(x0 + t0 * dx, xmin, xmax);
  const double ny0 = std::clamp(y0 + t0 * dy, ymin, ymax);
  const double nx1 = std::clamp(x0 + t1 * dx, xmin, xmax);
  const double ny1 = std::clamp(y0 + t1 * dy, ymin, ymax);
  x0 = nx0;
  y0 = ny0;
  x1 = nx1;
  y1 = ny1;
  return true;
}

int round_to_int(double v) { return static_cast<int>(std::floor(v + 0.5)); }

// A line of thickness t between two points in pixel coordinates (finite, any magnitude).
// Bresenham on the clipped end points; each step paints a span of t pixels across the main
// direction, so a horizontal line at row y covers rows y - (t - 1) / 2 .. y + t / 2.
void draw_line(const canvas& cv, double x0, double y0, double x1, double y1, int t, rgb8_color c) {
  // The margin lets the part of a thick line just outside the image still paint its inside.
  const double m = static_cast<double>(t) + 1.0;
  // An end far away (1e30) would leave Liang-Barsky with differences that have lost the
  // image-sized parts: pull it in along the line, from the other end, to a distance that
  // keeps them. When both ends are far the line is only as precise as its input anyway.
  const double cx = 0.5 * cv.width;
  const double cy = 0.5 * cv.height;
  const double far = 2.0 * (cv.width + cv.height) + 4.0 * m;
  const auto is_far = [&](double x, double y) {
    return std::abs(x - cx) > far || std::abs(y - cy) > far;
  };
  const auto pull_in = [&](double& x, double& y, double ox, double oy) {
    const double dx = x - ox;
    const double dy = y - oy;
    const double s = far / std::max(std::abs(dx), std::abs(dy));
    x = ox + dx * s;
    y = oy + dy * s;
  };
  const bool far0 = is_far(x0, y0);
  const bool far1 = is_far(x1, y1);
  if (far0 && !far1) pull_in(x0, y0, x1, y1);
  if (far1 && !far0) pull_in(x1, y1, x0, y0);
  if (!clip_segment(x0, y0, x1, y1, -m, -m, cv.width - 1 + m, cv.height - 1 + m)) return;
  int ax = round_to_int(x0);
  int ay = round_to_int(y0);
  const int bx = round_to_int(x1);
  const int by = round_to_int(y1);
  const int dx = std::abs(bx - ax);
  const int dy = -std::abs(by - ay);
  const int sx = ax < bx ? 1 : -1;
  const int sy = ay < by ? 1 : -1;
  const bool x_major = dx >= -dy;
  const int lo = (t - 1) / 2;
  const int hi = t / 2;
  int err = dx + dy;
  for (;;) {
    if (x_major)
      cv.column(ax, ay - lo, ay + hi, c);
    else
      cv.row(ax - lo, ax + hi, ay, c);
    if (ax == bx && ay == by) break;
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      ax += sx;
    }
    if (e2 <= dx) {
      err += dx;
      ay += sy;
    }
  }
}

// A filled disc: the pixels within `radius` of the point rounded to the nearest pixel.
void draw_disc(const canvas& cv, double x, double y, int radius, rgb8_color c) {
  const double r = radius;
  if (!(x >= -r - 1.0 && y >= -r - 1.0 && x <= cv.width + r && y <= cv.height + r)) return;
  const int cx = round_to_int(x);
  const int cy = round_to_int(y);
  for (int j = -radius; j <= radius; ++j) {
    int half = 0;
    while ((half + 1) * (half + 1) + j * j <= radius * radius) ++half;
    cv.row(cx - half, cx + half, cy + j, c);
  }
}

// A point of a frame in pixels; false when not seen.
bool to_pixels(const landmark& p, int width, int height, double& out_x, double& out_y) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y)) return false;
  out_x = static_cast<double>(p.x) * width;
  out_y = static_cast<double>(p.y) * height;
  return true;
}

struct drawer {
  canvas cv;
  const overlay_options& o;
  int thickness;
  int radius;

  // How a pose point is drawn: 0 not at all, 1 dim, 2 full.
  int pose_level(const landmark& p) const {
    if (!std::isfinite(p.visibility)) return 0;
    if (p.visibility < o.min_visibility)
      return o.low_visibility == overlay_low_visibility::skip ? 0 : 1;
    return 2;
  }

  rgb8_color side_color(int side) const {
    return side > 0 ? o.left_color : (side < 0 ? o.right_color : o.center_color);
  }

  void pose_lines(const landmark_frame& f) const {
    for (const landmark_connection& k : k_pose_connections) {
      const landmark& a = f.pose[k.a];
      const landmark& b = f.pose[k.b];
      const int level = std::min(pose_level(a), pose_level(b));
      double ax, ay, bx, by;
      if (level == 0 || !to_pixels(a, cv.width, cv.height, ax, ay) ||
          !to_pixels(b, cv.width, cv.height, bx, by))
        continue;
      const int sa = pose_landmark_side(k.a);
      const int sb = pose_landmark_side(k.b);
      // Both ends on one side (or one on the midline): that side; across the body: centre.
      const int side = sa * sb < 0 ? 0 : (sa != 0 ? sa : sb);
      const rgb8_color c = side_color(side);
      draw_line(cv, ax, ay, bx, by, thickness, level == 1 ? dimmed(c) : c);
    }
  }

  void pose_joints(const landmark_frame& f) const {
    for (int i = 0; i < k_pose_landmark_count; ++i) {
      const int level = pose_level(f.pose[i]);
      double x, y;
      if (level == 0 || !to_pixels(f.pose[i], cv.width, cv.height, x, y)) continue;
      const rgb8_color c = side_color(pose_landmark_side(i));
      draw_disc(cv, x, y, radius, level == 1 ? dimmed(c) : c);
    }
  }

  void hand_lines(const std::array<landmark, k_hand_landmark_count>& h, rgb8_color c) const {
    for (const landmark_connection& k : k_hand_connections) {
      double ax, ay, bx, by;
      if (!to_pixels(h[k.a], cv.width, cv.height, ax, ay) ||
          !to_pixels(h[k.b], cv.width, cv.height, bx, by))
        continue;
      draw_line(cv, ax, ay, bx, by, thickness, c);
    }
  }

  void hand_joints(const std::array<landmark, k_hand_landmark_count>& h, rgb8_color c) const {
    for (const landmark& p : h) {
      double x, y;
      if (to_pixels(p, cv.width, cv.height, x, y)) draw_disc(cv, x, y, radius, c);
    }
  }

  void face(const landmark_frame& f) const {
    const int n = std::clamp(f.face_count, 0, k_face_mesh_iris_count);
    const int r = thickness / 2;
    for (int i = 0; i < n; ++i) {
      double x, y;
      if (to_pixels(f.face[i], cv.width, cv.height, x, y)) draw_disc(cv, x, y, r, o.face_color);
    }
  }

  void rect(const normalized_rect& r) const {
    const double cx = static_cast<double>(r.x_center) * cv.width;
    const double cy = static_cast<double>(r.y_center) * cv.height;
    const double hw = 0.5 * static_cast<double>(r.width) * cv.width;
    const double hh = 0.5 * static_cast<double>(r.height) * cv.height;
    const double c = std::cos(static_cast<double>(r.rotation));
    const double s = std::sin(static_cast<double>(r.rotation));
    // Corners centre + R * (+-hw, +-hh), R rotating +x towards +y (clockwise on screen).
    double px[4], py[4];
    const double ux[4] = {-hw, hw, hw, -hw};
    const double uy[4] = {-hh, -hh, hh, hh};
    for (int i = 0; i < 4; ++i) {
      px[i] = cx + c * ux[i] - s * uy[i];
      py[i] = cy + s * ux[i] + c * uy[i];
      if (!std::isfinite(px[i]) || !std::isfinite(py[i])) return;
    }
    for (int i = 0; i < 4; ++i)
      draw_line(cv, px[i], py[i], px[(i + 1) % 4], py[(i + 1) % 4], thickness, o.rect_color);
  }

  // One frame's parts, in overlay_job's order; the face only when `with_face`.
  void frame(const landmark_frame& f, bool with_face) const {
    const bool pose = o.draw_pose && f.has(frame_part::pose);
    const bool left = o.draw_hands && f.has(frame_part::left_hand);
    const bool right = o.draw_hands && f.has(frame_part::right_hand);
    if (with_face && o.draw_face && f.has(frame_part::face)) face(f);
    if (pose) pose_lines(f);
    if (left) hand_lines(f.left_hand, o.left_color);
    if (right) hand_lines(f.right_hand, o.right_color);
    if (o.draw_joints) {
      if (pose) pose_joints(f);
      if (left) hand_joints(f.left_hand, o.left_color);
      if (right) hand_joints(f.right_hand, o.right_color);
    }
  }

  // The top centre (pixels) of the points of `f` that frame() draws inside the image; false
  // when there is none.
  bool top_of(const landmark_frame& f, double& out_x, double& out_top) const {
    double x0 = 0.0, x1 = 0.0, y0 = 0.0;
    bool any = false;
    const auto add = [&](const landmark& p) {
      double x, y;
      if (!to_pixels(p, cv.width, cv.height, x, y) || x < 0.0 || y < 0.0 || x > cv.width ||
          y > cv.height)
        return;
      x0 = any ? std::min(x0, x) : x;
      x1 = any ? std::max(x1, x) : x;
      y0 = any ? std::min(y0, y) : y;
      any = true;
    };
    if (o.draw_pose && f.has(frame_part::pose))
      for (const landmark& p : f.pose)
        if (pose_level(p) > 0) add(p);
    if (o.draw_hands && f.has(frame_part::left_hand))
      for (const landmark& p : f.left_hand) add(p);
    if (o.draw_hands && f.has(frame_part::right_hand))
      for (const landmark& p : f.right_hand) add(p);
    if (o.draw_face && f.has(frame_part::face))
      for (int i = 0; i < std::clamp(f.face_count, 0, k_face_mesh_iris_count); ++i) add(f.face[i]);
    out_x = 0.5 * (x0 + x1);
    out_top = y0;
    return any;
  }

  // `id` in decimal digits, seven segments of lines each (thickness + 1 pixels wide),
  // centred on x with its bottom thickness + 4 pixels above y (kept inside the image), over a
  // black outline.
  void label(int id, double x, double y, rgb8_color c) const {
    char digits[12];
    int n = 0;
    unsigned v = id < 0 ? 0u : static_cast<unsigned>(id);
    do {
      digits[n++] = static_cast<char>(v % 10);
      v /= 10;
    } while (v > 0 && n < 10);
    const int stroke = thickness + 1;
    const int h = 9 * thickness + 6;  // digit height
    const int w = (3 * h + 2) / 5;    // digit width
    const int gap = stroke + 3;       // between digits
    const int m = stroke / 2 + 2;     // room for the outline at the image's edges
    const int total = n * w + (n - 1) * gap;
    int left = round_to_int(x - 0.5 * total);
    int top = round_to_int(y) - thickness - 4 - h;
    left = std::max(m, std::min(left, cv.width - m - total));
    top = std::max(m, std::min(top, cv.height - m - h));
    constexpr rgb8_color k_black{0, 0, 0};
    for (int pass = 0; pass < 2; ++pass) {
      const int t = pass == 0 ? stroke + 2 : stroke;
      const int e = pass == 0 ? 1 : 0;  // the outline reaches one pixel past each end
      const rgb8_color col = pass == 0 ? k_black : c;
      for (int k = 0; k < n; ++k) {
        const std::uint8_t seg = overlay_digit_segments(digits[n - 1 - k]);
        const int xa = left + k * (w + gap), xb = xa + w - 1;
        const int ya = top, ym = top + (h - 1) / 2, yb = top + h - 1;
        // Segment i from (x, y) to (x, y): top, top right, bottom right, bottom, bottom left,
        // top left, middle.
        const int ends[7][4] = {{xa, ya, xb, ya}, {xb, ya, xb, ym}, {xb, ym, xb, yb},
                                {xa, yb, xb, yb}, {xa, ym, xa, yb}, {xa, ya, xa, ym},
                                {xa, ym, xb, ym}};
        for (int i = 0; i < 7; ++i) {
          if (!(seg & (1u << i))) continue;
          const int* q = ends[i];
          const int dx = q[2] > q[0] ? e : 0, dy = q[3] > q[1] ? e : 0;
          draw_line(cv, q[0] - dx, q[1] - dy, q[2] + dx, q[3] + dy, t, col);
        }
      }
    }
  }
};

}  // namespace

int overlay_auto_thickness(int width, int height) {
  const int m = std::min(width, height);
  return std::max(1, (m + 180) / 360);
}

bool overlay_job::validate() const {
  if (!image.data || image.width < 1 || image.height < 1 || image.width > k_max_side ||
      image.height > k_max_side)
    return false;
  if (image.stride_bytes < image.width * 3) return false;
  if (rect_count > 0 && !rects) return false;
  if (people_count > 0 && !people) return false;
  if (options.thickness < 0 || options.thickness > k_max_thickness) return false;
  if (options.joint_radius < -1 || options.joint_radius > k_max_thickness) return false;
  return true;
}

bool overlay_job::run() const {
  if (!validate()) return false;
  const int t =
      options.thickness > 0 ? options.thickness : overlay_auto_thickness(image.width, image.height);
  const drawer d{{image.data, image.width, image.height, image.stride_bytes},
                 options,
                 t,
                 options.joint_radius >= 0 ? options.joint_radius : t};
  if (options.draw_rects)
    for (std::size_t i = 0; i < rect_count; ++i) d.rect(rects[i]);
  if (people == nullptr) {
    if (frame) d.frame(*frame, true);
    return true;
  }
  constexpr rgb8_color k_black{0, 0, 0};
  overlay_options outline = options;
  outline.left_color = outline.right_color = outline.center_color = k_black;
  const drawer under{d.cv, outline, t + 2, d.radius + 1};
  for (std::size_t i = 0; i < people_count; ++i) {
    const landmark_frame& f = people[i];
    const rgb8_color c = person_color(f.person);
    overlay_options own = options;
    own.left_color = own.right_color = own.center_color = own.face_color = c;
    const drawer over{d.cv, own, t, d.radius};
    under.frame(f, false);
    over.frame(f, true);
    double x, top;
    if (over.top_of(f, x, top)) over.label(f.person, x, top, c);
  }
  return true;
}

}  // namespace avatarmap
