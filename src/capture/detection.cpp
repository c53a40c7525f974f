// Detection geometry of MediaPipe's graphs: SSD anchors, detection decoding, weighted NMS and
// regions of interest (detection.hpp), plus the pose graph's anchor options and region
// (pose_pipeline.hpp). Needs no ONNX Runtime.
#include "avatarmap/capture/detection.hpp"

#include <algorithm>
#include <cmath>

#include "avatarmap/capture/pose_pipeline.hpp"

namespace avatarmap {

namespace {

constexpr double k_pi = 3.14159265358979323846;

float anchor_scale(float min_scale, float max_scale, int index, int count) {
  if (count == 1) return (min_scale + max_scale) * 0.5f;
  return min_scale +
         (max_scale - min_scale) * static_cast<float>(index) / static_cast<float>(count - 1);
}

float sigmoid(float x) { return 1.f / (1.f + std::exp(-x)); }

}  // namespace

ssd_anchor_options pose_detection_anchor_options() { return ssd_anchor_options{}; }

bool generate_ssd_anchors(const ssd_anchor_options& o, std::vector<ssd_anchor>& out) {
  out.clear();
  const int n = o.num_layers;
  if (n <= 0 || static_cast<int>(o.strides.size()) < n || o.aspect_ratios.empty() ||
      o.input_width <= 0 || o.input_height <= 0)
    return false;
  const bool explicit_maps = !o.feature_map_width.empty() || !o.feature_map_height.empty();
  if (explicit_maps && (static_cast<int>(o.feature_map_width.size()) < n ||
                        static_cast<int>(o.feature_map_height.size()) < n))
    return false;
  for (int i = 0; i < n; ++i)
    if (o.strides[i] <= 0) return false;

  std::vector<float> widths, heights, aspects, scales;
  int layer = 0;
  while (layer < n) {
    widths.clear();
    heights.clear();
    aspects.clear();
    scales.clear();
    // Consecutive layers with the same stride share one feature map.
    int last = layer;
    while (last < n && o.strides[last] == o.strides[layer]) {
      const float scale = anchor_scale(o.min_scale, o.max_scale, last, n);
      if (last == 0 && o.reduce_boxes_in_lowest_layer) {
        aspects.insert(aspects.end(), {1.0f, 2.0f, 0.5f});
        scales.insert(scales.end(), {0.1f, scale, scale});
      } else {
        for (float a : o.aspect_ratios) {
          aspects.push_back(a);
          scales.push_back(scale);
        }
        if (o.interpolated_scale_aspect_ratio > 0.f) {
          const float next =
              last == n - 1 ? 1.0f : anchor_scale(o.min_scale, o.max_scale, last + 1, n);
          scales.push_back(std::sqrt(scale * next));
          aspects.push_back(o.interpolated_scale_aspect_ratio);
        }
      }
      ++last;
    }
    for (size_t i = 0; i < aspects.size(); ++i) {
      const float r = std::sqrt(aspects[i]);
      heights.push_back(scales[i] / r);
      widths.push_back(scales[i] * r);
    }
    int map_w, map_h;
    if (explicit_maps) {
      map_w = o.feature_map_width[layer];
      map_h = o.feature_map_height[layer];
    } else {
      const int stride = o.strides[layer];
      map_w = static_cast<int>(std::ceil(static_cast<float>(o.input_width) / stride));
      map_h = static_cast<int>(std::ceil(static_cast<float>(o.input_height) / stride));
    }
    for (int y = 0; y < map_h; ++y) {
      for (int x = 0; x < map_w; ++x) {
        for (size_t k = 0; k < aspects.size(); ++k) {
          ssd_anchor a;
          a.x_center = (static_cast<float>(x) + o.anchor_offset_x) / static_cast<float>(map_w);
          a.y_center = (static_cast<float>(y) + o.anchor_offset_y) / static_cast<float>(map_h);
          if (!o.fixed_anchor_size) {
            a.width = widths[k];
            a.height = heights[k];
          }
          out.push_back(a);
        }
      }
    }
    layer = last;
  }
  return true;
}

int decode_detections(const float* raw_boxes, const float* raw_scores, const ssd_anchor* anchors,
                      const detection_decode_options& o, std::vector<detection>& out) {
  out.clear();
  const int kp_count = std::min(o.num_keypoints, k_detection_max_keypoints);
  for (int i = 0; i < o.num_boxes; ++i) {
    float score = raw_scores[i];
    if (o.sigmoid_score) {
      if (o.score_clipping_thresh > 0.f)
        score = std::clamp(score, -o.score_clipping_thresh, o.score_clipping_thresh);
      score = sigmoid(score);
    }
    // NaN scores fail this test too, so non-finite outputs never become detections.
    if (!(score >= o.min_score_thresh)) continue;

    const float* r = raw_boxes + static_cast<size_t>(i) * o.num_coords;
    const ssd_anchor& a = anchors[i];
    const float* b = r + o.box_coord_offset;
    float bx = b[0], by = b[1], bw = b[2], bh = b[3];
    if (!o.reverse_output_order) {
      bx = b[1];
      by = b[0];
      bw = b[3];
      bh = b[2];
    }
    const float xc = bx / o.x_scale * a.width + a.x_center;
    const float yc = by / o.y_scale * a.height + a.y_center;
    const float w = bw / o.w_scale * a.width;
    const float h = bh / o.h_scale * a.height;

    detection d;
    d.score = score;
    d.xmin = xc - w * 0.5f;
    d.ymin = yc - h * 0.5f;
    d.width = w;
    d.height = h;
    d.keypoint_count = kp_count;
    for (int k = 0; k < kp_count; ++k) {
      const float* p = r + o.keypoint_coord_offset + k * o.num_values_per_keypoint;
      float px = p[0], py = p[1];
      if (!o.reverse_output_order) std::swap(px, py);
      d.keypoints[2 * k] = px / o.x_scale * a.width + a.x_center;
      d.keypoints[2 * k + 1] = py / o.y_scale * a.height + a.y_center;
    }
    out.push_back(d);
  }
  return static_cast<int>(out.size());
}

float detection_iou(const detection& a, const detection& b) {
  const float ix0 = std::max(a.xmin, b.xmin);
  const float iy0 = std::max(a.ymin, b.ymin);
  const float ix1 = std::min(a.xmin + a.width, b.xmin + b.width);
  const float iy1 = std::min(a.ymin + a.height, b.ymin + b.height);
  if (!(ix1 > ix0 && iy1 > iy0)) return 0.f;
  const float inter = (ix1 - ix0) * (iy1 - iy0);
  const float uni = a.width * a.height + b.width * b.height - inter;
  return uni > 0.f ? inter / uni : 0.f;
}

int weighted_non_max_suppression(const std::vector<detection>& detections, float iou_threshold,
                                 int max_detections, std::vector<detection>& out,
                                 std::vector<int>& scratch) {
  out.clear();
  scratch.clear();
  for (int i = 0; i < static_cast<int>(detections.size()); ++i) scratch.push_back(i);
  // Equal scores keep the decoder's (anchor) order as MediaPipe's sort does in practice: the
  // order of a stable sort, without the buffer std::stable_sort allocates (the detectors run
  // on the per-frame path when several people are followed).
  std::sort(scratch.begin(), scratch.end(), [&](int a, int b) {
    const float sa = detections[a].score, sb = detections[b].score;
    return sa > sb || (!(sb > sa) && a < b);
  });
  size_t remaining = scratch.size();
  while (remaining > 0) {
    if (max_detections > 0 && static_cast<int>(out.size()) >= max_detections) break;
    const detection& top = detections[scratch[0]];
    detection weighted = top;
    float total = 0.f, x0 = 0.f, y0 = 0.f, x1 = 0.f, y1 = 0.f;
    std::array<float, 2 * k_detection_max_keypoints> kp{};
    size_t kept = 0;
    // Partition in place: the overlapping group is averaged, the rest is compacted to the
    // front in score order for the next round.
    for (size_t i = 0; i < remaining; ++i) {
      const detection& d = detections[scratch[i]];
      if (detection_iou(d, top) > iou_threshold) {
        total += d.score;
        x0 += d.xmin * d.score;
        y0 += d.ymin * d.score;
        x1 += (d.xmin + d.width) * d.score;
        y1 += (d.ymin + d.height) * d.score;
        for (int k = 0; k < 2 * top.keypoint_count; ++k) kp[k] += d.keypoints[k] * d.score;
      } else {
        scratch[kept++] = scratch[i];
      }
    }
    if (total > 0.f) {
      weighted.xmin = x0 / total;
      weighted.ymin = y0 / total;
      weighted.width = x1 / total - weighted.xmin;
      weighted.height = y1 / total - weighted.ymin;
      for (int k = 0; k < 2 * top.keypoint_count; ++k) weighted.keypoints[k] = kp[k] / total;
    }
    out.push_back(weighted);
    // A degenerate top box (zero area) overlaps nothing, not even itself: drop it so the
    // loop always progresses, as MediaPipe's "size unchanged" exit does.
    if (kept == remaining) break;
    remaining = kept;
  }
  return static_cast<int>(out.size());
}

float normalize_radians(float angle) {
  const double a = angle;
  return static_cast<float>(a - 2.0 * k_pi * std::floor((a + k_pi) / (2.0 * k_pi)));
}

normalized_rect roi_from_alignment_points(float center_x, float center_y, float scale_x_point,
                                          float scale_y_point, int image_width, int image_height,
                                          const roi_from_points_options& o) {
  const float w = static_cast<float>(image_width);
  const float h = static_cast<float>(image_height);
  const float x0 = center_x * w, y0 = center_y * h;
  const float x1 = scale_x_point * w, y1 = scale_y_point * h;
  const float box = std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0)) * 2.f;
  normalized_rect r;
  r.x_center = x0 / w;
  r.y_center = y0 / h;
  r.width = box / w;
  r.height = box / h;
  r.rotation = rotation_from_points(center_x, center_y, scale_x_point, scale_y_point, image_width,
                                    image_height, o.target_angle);
  rect_transform_options t;
  t.scale_x = o.scale_x;
  t.scale_y = o.scale_y;
  t.square_long = o.square_long;
  return transform_rect(r, image_width, image_height, t);
}

float rotation_from_points(float x0, float y0, float x1, float y1, int image_width,
                           int image_height, float target_angle) {
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  // y is down in the image, so the vector's angle is measured with -dy.
  return normalize_radians(target_angle - std::atan2(-(y1 - y0) * h, (x1 - x0) * w));
}

normalized_rect transform_rect(const normalized_rect& r, int image_width, int image_height,
                               const rect_transform_options& o) {
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  normalized_rect out = r;
  if (o.shift_x != 0.f || o.shift_y != 0.f) {
    // The shift runs along the region's own axes, measured in pixels.
    const float c = std::cos(r.rotation), s = std::sin(r.rotation);
    const float dx = w * r.width * o.shift_x, dy = h * r.height * o.shift_y;
    out.x_center += (dx * c - dy * s) / w;
    out.y_center += (dx * s + dy * c) / h;
  }
  if (o.square_long) {
    const float side = std::max(r.width * w, r.height * h);
    out.width = side / w;
    out.height = side / h;
  }
  out.width *= o.scale_x;
  out.height *= o.scale_y;
  return out;
}

normalized_rect detection_to_rect(const detection& d, int start_keypoint, int end_keypoint,
                                  float target_angle, int image_width, int image_height) {
  normalized_rect r;
  r.x_center = d.xmin + d.width * 0.5f;
  r.y_center = d.ymin + d.height * 0.5f;
  r.width = d.width;
  r.height = d.height;
  r.rotation = 0.f;
  if (start_keypoint >= 0 && end_keypoint >= 0 && start_keypoint < d.keypoint_count &&
      end_keypoint < d.keypoint_count)
    r.rotation =
        rotation_from_points(d.keypoints[2 * start_keypoint], d.keypoints[2 * start_keypoint + 1],
                             d.keypoints[2 * end_keypoint], d.keypoints[2 * end_keypoint + 1],
                             image_width, image_height, target_angle);
  return r;
}

normalized_rect rotated_bounding_rect(const float* xy, int count, float rotation, int image_width,
                                      int image_height) {
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  normalized_rect r;
  r.rotation = rotation;
  if (count <= 0) return r;
  // Centre of the axis-aligned box, in pixels; the points are turned about it by -rotation.
  float ax0 = xy[0] * w, ax1 = ax0, ay0 = xy[1] * h, ay1 = ay0;
  for (int i = 1; i < count; ++i) {
    ax0 = std::min(ax0, xy[2 * i] * w);
    ax1 = std::max(ax1, xy[2 * i] * w);
    ay0 = std::min(ay0, xy[2 * i + 1] * h);
    ay1 = std::max(ay1, xy[2 * i + 1] * h);
  }
  const float cx = (ax0 + ax1) * 0.5f, cy = (ay0 + ay1) * 0.5f;
  const float rc = std::cos(-rotation), rs = std::sin(-rotation);
  float x0 = 0.f, x1 = 0.f, y0 = 0.f, y1 = 0.f;
  for (int i = 0; i < count; ++i) {
    const float ox = xy[2 * i] * w - cx, oy = xy[2 * i + 1] * h - cy;
    const float px = ox * rc - oy * rs, py = ox * rs + oy * rc;
    if (i == 0) {
      x0 = x1 = px;
      y0 = y1 = py;
    }
    x0 = std::min(x0, px);
    x1 = std::max(x1, px);
    y0 = std::min(y0, py);
    y1 = std::max(y1, py);
  }
  const float pcx = (x0 + x1) * 0.5f, pcy = (y0 + y1) * 0.5f;
  const float c = std::cos(rotation), s = std::sin(rotation);
  r.x_center = (pcx * c - pcy * s + cx) / w;
  r.y_center = (pcx * s + pcy * c + cy) / h;
  r.width = (x1 - x0) / w;
  r.height = (y1 - y0) / h;
  return r;
}

bool points_to_rect(const float* xy, int count, int stride_floats, int start, int end,
                    float target_angle, int image_width, int image_height, normalized_rect& out) {
  if (xy == nullptr || count < 1 || stride_floats < 2 || start < 0 || end < 0 || start >= count ||
      end >= count)
    return false;
  float x0 = xy[0], x1 = xy[0], y0 = xy[1], y1 = xy[1];
  for (int i = 0; i < count; ++i) {
    const float x = xy[static_cast<size_t>(i) * stride_floats];
    const float y = xy[static_cast<size_t>(i) * stride_floats + 1];
    if (!std::isfinite(x) || !std::isfinite(y)) return false;
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  out.x_center = (x0 + x1) * 0.5f;
  out.y_center = (y0 + y1) * 0.5f;
  out.width = x1 - x0;
  out.height = y1 - y0;
  const float* a = xy + static_cast<size_t>(start) * stride_floats;
  const float* b = xy + static_cast<size_t>(end) * stride_floats;
  out.rotation =
      rotation_from_points(a[0], a[1], b[0], b[1], image_width, image_height, target_angle);
  return true;
}

detection project_detection(const crop_transform& tr, const detection& d) {
  const float tw = static_cast<float>(tr.tensor_width), th = static_cast<float>(tr.tensor_height);
  detection out = d;
  for (int k = 0; k < d.keypoint_count; ++k) {
    const crop_point p =
        project_to_image(tr, {d.keypoints[2 * k] * tw, d.keypoints[2 * k + 1] * th, 0.f});
    out.keypoints[2 * k] = p.x;
    out.keypoints[2 * k + 1] = p.y;
  }
  const float cx[4] = {d.xmin, d.xmin + d.width, d.xmin + d.width, d.xmin};
  const float cy[4] = {d.ymin, d.ymin, d.ymin + d.height, d.ymin + d.height};
  float x0 = 0.f, x1 = 0.f, y0 = 0.f, y1 = 0.f;
  for (int i = 0; i < 4; ++i) {
    const crop_point p = project_to_image(tr, {cx[i] * tw, cy[i] * th, 0.f});
    x0 = i == 0 ? p.x : std::min(x0, p.x);
    x1 = i == 0 ? p.x : std::max(x1, p.x);
    y0 = i == 0 ? p.y : std::min(y0, p.y);
    y1 = i == 0 ? p.y : std::max(y1, p.y);
  }
  out.xmin = x0;
  out.ymin = y0;
  out.width = x1 - x0;
  out.height = y1 - y0;
  return out;
}

float normalized_rect_iou(const normalized_rect& a, const normalized_rect& b, int image_width,
                          int image_height) {
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  const float ax0 = (a.x_center - a.width * 0.5f) * w, ax1 = (a.x_center + a.width * 0.5f) * w;
  const float ay0 = (a.y_center - a.height * 0.5f) * h, ay1 = (a.y_center + a.height * 0.5f) * h;
  const float bx0 = (b.x_center - b.width * 0.5f) * w, bx1 = (b.x_center + b.width * 0.5f) * w;
  const float by0 = (b.y_center - b.height * 0.5f) * h, by1 = (b.y_center + b.height * 0.5f) * h;
  const float ix = std::min(ax1, bx1) - std::max(ax0, bx0);
  const float iy = std::min(ay1, by1) - std::max(ay0, by0);
  if (!(ix > 0.f && iy > 0.f)) return 0.f;
  const float inter = ix * iy;
  const float uni = (ax1 - ax0) * (ay1 - ay0) + (bx1 - bx0) * (by1 - by0) - inter;
  return uni > 0.f ? inter / uni : 0.f;
}

bool normalized_rect_contains(const normalized_rect& r, float x, float y, int image_width,
                              int image_height) {
  const float w = static_cast<float>(image_width), h = static_cast<float>(image_height);
  const float dx = (x - r.x_center) * w, dy = (y - r.y_center) * h;
  // Into the region's own axes: rotate by -rotation.
  const float c = std::cos(r.rotation), s = std::sin(r.rotation);
  const float u = dx * c + dy * s, v = -dx * s + dy * c;
  return std::fabs(u) <= r.width * w * 0.5f && std::fabs(v) <= r.height * h * 0.5f;
}

normalized_rect pose_detection_to_roi(const detection& d, int image_width, int image_height,
                                      const roi_from_points_options& options) {
  return roi_from_alignment_points(d.keypoints[0], d.keypoints[1], d.keypoints[2], d.keypoints[3],
                                   image_width, image_height, options);
}

}  // namespace avatarmap
