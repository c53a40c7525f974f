// .vrma reader: the file is opened and checked by gltf_detail (container, JSON depth, index
// ranges, URIs) and parsed by tinygltf; everything after parsing (accessors, the extension,
// the node tree) is checked here, because a malformed file must give an error, never a crash.
// The extension is read from the checked JSON (tinygltf truncates big integers to int).
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <glm/gtc/quaternion.hpp>
#include <string>
#include <vector>

#include "avatarmap/export/vrma.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "rig/gltf_document.hpp"

namespace avatarmap {
namespace {

constexpr const char* k_extension = "VRMC_vrm_animation";

enum class interp { linear, step, cubic };

// One sampler's data: times and values (components per value: 1, 3 or 4). For CUBICSPLINE
// each key holds in-tangent, value, out-tangent (3 * comps floats).
struct track {
  std::vector<float> times;
  std::vector<float> values;
  int comps = 0;
  interp mode = interp::linear;
};

// Where a node's animated local transform comes from (-1: its rest value).
struct node_tracks {
  int rotation = -1;
  int translation = -1;
  int scale = -1;
};

struct trs {
  glm::dvec3 t{0.0};
  glm::dquat r{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 s{1.0};
};

// Reads accessor `index` as floats with `comps` components per element. Accepts FLOAT and
// the normalised integer types glTF allows for animation outputs.
bool read_accessor(const tinygltf::Model& m, int index, int type, std::vector<float>& out,
                   std::string& err) {
  std::string where = "accessor " + std::to_string(index);
  if (index < 0 || index >= static_cast<int>(m.accessors.size())) {
    err = where + " does not exist";
    return false;
  }
  const tinygltf::Accessor& a = m.accessors[index];
  int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  if (a.type != type || comps <= 0) {
    err = where + " has the wrong type (expected " +
          (type == TINYGLTF_TYPE_SCALAR
               ? std::string("SCALAR")
               : "VEC" + std::to_string(tinygltf::GetNumComponentsInType(type))) +
          ")";
    return false;
  }
  if (a.sparse.isSparse) {
    err = where + " is sparse (not supported)";
    return false;
  }
  int csize = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
  bool is_float = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (csize <= 0 || csize > 4 || a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT ||
      (!is_float && !a.normalized)) {
    err = where + " has an unsupported component type " + std::to_string(a.componentType) +
          " (expected FLOAT or a normalised integer)";
    return false;
  }
  if (a.bufferView < 0 || a.bufferView >= static_cast<int>(m.bufferViews.size())) {
    err = where + " has no valid bufferView";
    return false;
  }
  const tinygltf::BufferView& v = m.bufferViews[a.bufferView];
  if (v.buffer < 0 || v.buffer >= static_cast<int>(m.buffers.size())) {
    err = where + ": bufferView " + std::to_string(a.bufferView) + " has no valid buffer";
    return false;
  }
  const std::vector<unsigned char>& data = m.buffers[v.buffer].data;
  std::size_t elem = static_cast<std::size_t>(csize) * static_cast<std::size_t>(comps);
  std::size_t stride = v.byteStride ? v.byteStride : elem;
  if (stride < elem || v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset ||
      a.byteOffset > v.byteLength) {
    err = where + ": bufferView " + std::to_string(a.bufferView) + " is out of bounds";
    return false;
  }
  if (a.count > 0 && ((a.count - 1) > (v.byteLength - a.byteOffset) / stride ||
                      (a.count - 1) * stride + elem > v.byteLength - a.byteOffset)) {
    err = where + " (" + std::to_string(a.count) + " elements) runs past its bufferView";
    return false;
  }
  out.resize(a.count * static_cast<std::size_t>(comps));
  const unsigned char* base = data.data() + v.byteOffset + a.byteOffset;
  for (std::size_t i = 0; i < a.count; ++i) {
    const unsigned char* p = base + i * stride;
    for (int c = 0; c < comps; ++c) {
      const unsigned char* q = p + static_cast<std::size_t>(c) * csize;
      float f = 0.f;
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
          std::memcpy(&f, q, 4);
          break;
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          std::int8_t x;
          std::memcpy(&x, q, 1);
          f = std::max(static_cast<float>(x) / 127.f, -1.f);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          f = static_cast<float>(*q) / 255.f;
          break;
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          std::int16_t x;
          std::memcpy(&x, q, 2);
          f = std::max(static_cast<float>(x) / 32767.f, -1.f);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          std::uint16_t x;
          std::memcpy(&x, q, 2);
          f = static_cast<float>(x) / 65535.f;
          break;
        }
        default:
          break;
      }
      out[i * comps + c] = f;
    }
  }
  return true;
}

// Value of a track at time t (out has t.comps elements).
void sample(const track& tr, double t, double* out) {
  const int n = tr.comps;
  const std::size_t keys = tr.times.size();
  const int per_key = tr.mode == interp::cubic ? 3 * n : n;
  const int value_at = tr.mode == interp::cubic ? n : 0;  // the value between the tangents
  auto value = [&](std::size_t k, int c) {
    return static_cast<double>(tr.values[k * per_key + value_at + c]);
  };
  std::size_t hi = static_cast<std::size_t>(
      std::upper_bound(tr.times.begin(), tr.times.end(), static_cast<float>(t)) - tr.times.begin());
  // Key times come from the same floats, so a frame at a key lands exactly on it (u = 0).
  if (hi == 0 || hi == keys || tr.mode == interp::step) {
    std::size_t k = hi == 0 ? 0 : hi - 1;
    for (int c = 0; c < n; ++c) out[c] = value(k, c);
    return;
  }
  std::size_t lo = hi - 1;
  double t0 = tr.times[lo], t1 = tr.times[hi];
  double dt = t1 - t0;
  double u = dt > 0.0 ? std::clamp((t - t0) / dt, 0.0, 1.0) : 0.0;
  if (tr.mode == interp::cubic) {
    double u2 = u * u, u3 = u2 * u;
    double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    for (int c = 0; c < n; ++c) {
      double out_tan = tr.values[lo * per_key + 2 * n + c];  // b_k
      double in_tan = tr.values[hi * per_key + c];           // a_k+1
      out[c] = h00 * value(lo, c) + h10 * dt * out_tan + h01 * value(hi, c) + h11 * dt * in_tan;
    }
    if (n == 4) {
      double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
      if (len > 0.0)
        for (int c = 0; c < 4; ++c) out[c] /= len;
    }
    return;
  }
  if (n == 4) {
    glm::dquat a(value(lo, 3), value(lo, 0), value(lo, 1), value(lo, 2));
    glm::dquat b(value(hi, 3), value(hi, 0), value(hi, 1), value(hi, 2));
    a = glm::normalize(a);
    b = glm::normalize(b);
    if (glm::dot(a, b) < 0.0) b = -b;
    glm::dquat q = glm::normalize(glm::slerp(a, b, u));
    out[0] = q.x;
    out[1] = q.y;
    out[2] = q.z;
    out[3] = q.w;
    return;
  }
  for (int c = 0; c < n; ++c) out[c] = value(lo, c) + (value(hi, c) - value(lo, c)) * u;
}

glm::dmat4 to_matrix(const trs& x) {
  glm::dmat4 m = glm::mat4_cast(x.r);
  for (int c = 0; c < 3; ++c) m[c] *= x.s[c];
  m[3] = glm::dvec4(x.t, 1.0);
  return m;
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

using json = nlohmann::json;

// Member `key` of an object, or nullptr.
const json* member(const json& v, const char* key) {
  if (!v.is_object()) return nullptr;
  const auto it = v.find(key);
  return it == v.end() ? nullptr : &*it;
}

// Reads {"node": int} from an extension object: the index, or -1 when absent or not a whole
// number in [0, node_count) (2^40 is out of range, never wrapped to a valid node).
int node_of(const json& entry, int node_count) {
  const json* n = member(entry, "node");
  if (!n || !n->is_number()) return -1;
  const double d = n->get<double>();
  if (!(d >= 0.0 && d < static_cast<double>(node_count)) || d != std::floor(d)) return -1;
  return static_cast<int>(d);
}

status read_impl(const std::string& path, vrma_clip& out, const vrma_read_options& options) {
  // The file's content: a parse error (the options are checked first, as arguments).
  auto fail = [&path](const std::string& what) { return status::parse_error(path + ": " + what); };
  if (!std::isfinite(options.fps) || options.fps < 0.0)
    return status::invalid_argument(path + ": fps must be 0 (key times) or positive");
  if (!std::isfinite(options.hips_height) || options.hips_height < 0.f)
    return status::invalid_argument(path + ": hips_height must be 0 (keep) or positive");

  gltf_detail::gltf_document doc;
  if (status s = gltf_detail::open_gltf_document(path, doc); !s) return s;
  tinygltf::Model model;
  if (status s = gltf_detail::parse_gltf_model(doc, model); !s) return s;

  // ---- the extension ----
  const json* extensions = member(doc.json, "extensions");
  const json* ext_ptr = extensions ? member(*extensions, k_extension) : nullptr;
  if (!ext_ptr || !ext_ptr->is_object())
    return fail("no VRMC_vrm_animation extension (not a VRM animation)");
  const json& ext = *ext_ptr;
  const json* spec_value = member(ext, "specVersion");
  if (!spec_value || !spec_value->is_string()) return fail("VRMC_vrm_animation has no specVersion");
  const std::string spec = spec_value->get<std::string>();
  if (spec != "1.0" && spec != "1.0-draft")
    return fail("unsupported VRMC_vrm_animation specVersion \"" + spec + "\" (expected 1.0)");
  const json* humanoid = member(ext, "humanoid");
  const json* bones_ptr = humanoid ? member(*humanoid, "humanBones") : nullptr;
  if (!bones_ptr || !bones_ptr->is_object())
    return fail("VRMC_vrm_animation has no humanoid.humanBones object");
  const int node_count = static_cast<int>(model.nodes.size());
  const json& bones = *bones_ptr;

  vrma_clip clip;
  clip.generator = model.asset.generator;
  std::array<int, k_bone_count> bone_node;
  bone_node.fill(-1);
  for (auto it = bones.begin(); it != bones.end(); ++it) {
    const std::string& name = it.key();
    const int node = node_of(it.value(), node_count);
    if (node < 0)
      return fail("humanoid.humanBones." + name + " does not name a valid node (a whole number " +
                  "below the file's " + std::to_string(node_count) + " nodes)");
    auto b = bone_from_name(name);
    if (!b || !is_vrma_bone(*b)) continue;  // unknown names and eyes: ignored
    bone_node[idx(*b)] = node;
    clip.has_bone[idx(*b)] = true;
  }
  if (bone_node[idx(bone::hips)] < 0) return fail("humanoid.humanBones has no hips");

  std::array<int, k_expression_count> expr_node;
  expr_node.fill(-1);
  std::array<int, k_blendshape_count> shape_node;
  shape_node.fill(-1);
  if (const json* exprs = member(ext, "expressions"); exprs && exprs->is_object()) {
    for (const char* group : {"preset", "custom"}) {
      const json* g = member(*exprs, group);
      if (!g || !g->is_object()) continue;
      for (auto it = g->begin(); it != g->end(); ++it) {
        const std::string& name = it.key();
        const int node = node_of(it.value(), node_count);
        if (node < 0)
          return fail(std::string("expressions.") + group + "." + name +
                      " does not name a valid node");
        clip.expression_names.push_back(name);
        // browDownLeft/Right are both a proxy expression and an ARKit shape: both are set.
        if (auto sh = blendshape_from_name(name)) {
          shape_node[idx(*sh)] = node;
          clip.has_blendshape[idx(*sh)] = true;
        }
        auto e = expression_from_name(name);
        if (!e || !is_vrma_expression(*e)) continue;
        expr_node[idx(*e)] = node;
        clip.has_expression[idx(*e)] = true;
      }
    }
  }
  int look_node = -1;
  if (const json* look = member(ext, "lookAt"); look && look->is_object()) {
    look_node = node_of(*look, node_count);
    if (look_node < 0)
      return fail("lookAt does not name a valid node (a whole number below the file's " +
                  std::to_string(node_count) + " nodes)");
  }

  // ---- the node tree ----
  std::vector<int> parent(node_count, -1);
  for (int i = 0; i < node_count; ++i)
    for (int c : model.nodes[i].children) {
      if (c < 0 || c >= node_count)
        return fail("node " + std::to_string(i) + " has an invalid child");
      if (parent[c] != -1 || c == i)
        return fail("node " + std::to_string(c) + " has more than one parent");
      parent[c] = i;
    }
  // Parent-first order (also rejects cycles).
  std::vector<int> order;
  order.reserve(node_count);
  {
    std::vector<char> placed(node_count, 0);
    for (int i = 0; i < node_count; ++i)
      if (parent[i] < 0) {
        std::vector<int> stack{i};
        while (!stack.empty()) {
          int n = stack.back();
          stack.pop_back();
          placed[n] = 1;
          order.push_back(n);
          for (int c : model.nodes[n].children) stack.push_back(c);
        }
      }
    if (static_cast<int>(order.size()) != node_count) return fail("the node hierarchy has a cycle");
  }
  std::vector<trs> rest(node_count);
  for (int i = 0; i < node_count; ++i) {
    const tinygltf::Node& n = model.nodes[i];
    trs& x = rest[i];
    if (n.matrix.size() == 16) {
      glm::dmat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[c * 4 + r];
      x.t = glm::dvec3(m[3]);
      glm::dmat3 rs(m);
      for (int c = 0; c < 3; ++c) {
        x.s[c] = glm::length(rs[c]);
        if (x.s[c] > 0.0) rs[c] /= x.s[c];
      }
      if (glm::determinant(rs) < 0.0) {
        x.s[0] = -x.s[0];
        rs[0] = -rs[0];
      }
      x.r = glm::quat_cast(rs);
    } else {
      if (n.translation.size() == 3) x.t = {n.translation[0], n.translation[1], n.translation[2]};
      if (n.rotation.size() == 4)
        x.r = glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
      if (n.scale.size() == 3) x.s = {n.scale[0], n.scale[1], n.scale[2]};
    }
    std::vector<double> check{x.t.x, x.t.y, x.t.z, x.r.w, x.r.x, x.r.y, x.r.z, x.s.x, x.s.y, x.s.z};
    if (!all_finite(check) || glm::dot(x.r, x.r) < 1e-12)
      return fail("node " + std::to_string(i) + " has a non-finite or zero transform");
    x.r = glm::normalize(x.r);
  }

  // ---- the animation ----
  if (model.animations.empty())
    return fail("no animation (a VRMA's motion is its first animation)");
  const tinygltf::Animation& anim = model.animations[0];
  std::vector<track> tracks(anim.samplers.size());
  std::vector<char> sampler_used(anim.samplers.size(), 0);
  std::vector<node_tracks> node_anim(node_count);
  for (std::size_t ci = 0; ci < anim.channels.size(); ++ci) {
    const tinygltf::AnimationChannel& ch = anim.channels[ci];
    std::string where = "animation 0 channel " + std::to_string(ci);
    if (ch.target_node < 0 || ch.target_node >= node_count) {
      if (ch.target_node < 0) continue;  // targets something else (extension): not ours
      return fail(where + " targets a missing node");
    }
    int comps = ch.target_path == "rotation"                                     ? 4
                : (ch.target_path == "translation" || ch.target_path == "scale") ? 3
                                                                                 : 0;
    if (comps == 0) continue;  // morph weights: ignored
    if (ch.sampler < 0 || ch.sampler >= static_cast<int>(anim.samplers.size()))
      return fail(where + " has an invalid sampler");
    node_tracks& nt = node_anim[ch.target_node];
    (comps == 4                        ? nt.rotation
     : ch.target_path == "translation" ? nt.translation
                                       : nt.scale) = ch.sampler;
    if (sampler_used[ch.sampler]) {
      if (tracks[ch.sampler].comps != comps)
        return fail(where + ": sampler " + std::to_string(ch.sampler) +
                    " is used for values of different sizes");
      continue;
    }
    sampler_used[ch.sampler] = 1;
    const tinygltf::AnimationSampler& s = anim.samplers[ch.sampler];
    track& tr = tracks[ch.sampler];
    tr.comps = comps;
    if (s.interpolation == "STEP")
      tr.mode = interp::step;
    else if (s.interpolation == "CUBICSPLINE")
      tr.mode = interp::cubic;
    else if (s.interpolation.empty() || s.interpolation == "LINEAR")
      tr.mode = interp::linear;
    else
      return fail(where + ": unknown interpolation \"" + s.interpolation + "\"");
    std::string aerr;
    std::string swhere = "animation 0 sampler " + std::to_string(ch.sampler);
    if (!read_accessor(model, s.input, TINYGLTF_TYPE_SCALAR, tr.times, aerr))
      return fail(swhere + " input: " + aerr);
    if (!read_accessor(model, s.output, comps == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                       tr.values, aerr))
      return fail(swhere + " output: " + aerr);
    if (tr.times.empty()) return fail(swhere + " has no keys");
    for (std::size_t k = 0; k < tr.times.size(); ++k)
      if (!std::isfinite(tr.times[k]) || tr.times[k] < 0.f ||
          (k > 0 && !(tr.times[k] > tr.times[k - 1])))
        return fail(swhere + ": key times must be finite, non-negative and increasing (key " +
                    std::to_string(k) + ")");
    std::size_t per_key = static_cast<std::size_t>(comps) * (tr.mode == interp::cubic ? 3 : 1);
    if (tr.values.size() != tr.times.size() * per_key)
      return fail(swhere + ": output has " + std::to_string(tr.values.size() / comps) +
                  " values for " + std::to_string(tr.times.size()) + " keys");
    for (float v : tr.values)
      if (!std::isfinite(v)) return fail(swhere + ": output has non-finite values");
  }

  // ---- key times ----
  std::vector<double> times;
  for (std::size_t i = 0; i < tracks.size(); ++i)
    if (sampler_used[i]) times.insert(times.end(), tracks[i].times.begin(), tracks[i].times.end());
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  if (times.empty()) return fail("the first animation has no channel that moves a node");
  clip.duration = times.back();
  if (options.fps > 0.0) {
    // Bounded like every resampling: a key at 1e9 s must not ask for 3e10 frames.
    const double t0 = times.front(), t_last = times.back();
    std::size_t count = 0;
    if (status s = resampled_frame_count(t0, t_last, options.fps, path, count); !s) return s;
    times.resize(count);
    for (std::size_t k = 0; k < count; ++k)
      times[k] = resampled_frame_time(t0, t_last, k, options.fps);
  }

  // ---- rest pose ----
  std::vector<glm::dquat> rest_world_rot(node_count);
  std::vector<glm::dmat4> world(node_count);
  for (int n : order) {
    int p = parent[n];
    rest_world_rot[n] = p < 0 ? rest[n].r : rest_world_rot[p] * rest[n].r;
    world[n] = p < 0 ? to_matrix(rest[n]) : world[p] * to_matrix(rest[n]);
  }
  const int hips_node = bone_node[idx(bone::hips)];
  clip.rest_hips_height = static_cast<float>(world[hips_node][3].y);
  double hips_scale = 1.0;
  if (options.hips_height > 0.f && clip.rest_hips_height > 0.f)
    hips_scale = static_cast<double>(options.hips_height) / clip.rest_hips_height;

  // ---- frames ----
  std::vector<glm::dquat> world_rot(node_count);
  std::vector<trs> local(node_count);
  std::array<glm::dquat, k_bone_count> norm_world;
  clip.frames.resize(times.size());
  double v[4];
  for (std::size_t f = 0; f < times.size(); ++f) {
    const double t = times[f];
    for (int n : order) {
      trs x = rest[n];
      const node_tracks& nt = node_anim[n];
      if (nt.rotation >= 0) {
        sample(tracks[nt.rotation], t, v);
        x.r = glm::dquat(v[3], v[0], v[1], v[2]);
        if (glm::dot(x.r, x.r) < 1e-12)
          return fail("node " + std::to_string(n) + " has a zero rotation key");
        x.r = glm::normalize(x.r);
      }
      if (nt.translation >= 0) {
        sample(tracks[nt.translation], t, v);
        x.t = {v[0], v[1], v[2]};
      }
      if (nt.scale >= 0) {
        sample(tracks[nt.scale], t, v);
        x.s = {v[0], v[1], v[2]};
      }
      local[n] = x;
      int p = parent[n];
      world_rot[n] = p < 0 ? x.r : world_rot[p] * x.r;
      world[n] = p < 0 ? to_matrix(x) : world[p] * to_matrix(x);
    }
    proxy_pose& pose = clip.frames[f];
    pose.set_rest();
    pose.t = t;
    for (int b = 0; b < k_bone_count; ++b) {
      int n = bone_node[b];
      norm_world[b] =
          n < 0 ? glm::dquat(1, 0, 0, 0) : world_rot[n] * glm::inverse(rest_world_rot[n]);
    }
    for (int b = 0; b < k_bone_count; ++b) {
      if (bone_node[b] < 0) continue;
      int p = bone_parent(b);
      while (p != k_no_parent && bone_node[p] < 0) p = bone_parent(p);
      glm::dquat q = p == k_no_parent ? norm_world[b] : glm::inverse(norm_world[p]) * norm_world[b];
      q = glm::normalize(q);
      if (q.w < 0.0) q = -q;
      pose.rotations[b] = glm::quat(static_cast<float>(q.w), static_cast<float>(q.x),
                                    static_cast<float>(q.y), static_cast<float>(q.z));
      pose.confidence[b] = 1.f;
    }
    glm::dvec3 hp = glm::dvec3(world[hips_node][3]);
    pose.hips_position = glm::vec3(hp * hips_scale);
    for (int e = 0; e < k_expression_count; ++e) {
      int n = expr_node[e];
      if (n < 0) continue;
      pose.expressions[e] = static_cast<float>(std::clamp(local[n].t.x, 0.0, 1.0));
    }
    for (int sh = 0; sh < k_blendshape_count; ++sh) {
      int n = shape_node[sh];
      if (n < 0) continue;
      pose.blendshapes[sh] = static_cast<float>(std::clamp(local[n].t.x, 0.0, 1.0));
    }
    if (look_node >= 0) {
      glm::dquat gaze(1, 0, 0, 0);
      bool have = false;
      if (node_anim[look_node].rotation >= 0) {
        gaze = local[look_node].r;  // three-vrm's reading (and write_vrma's)
        have = true;
      } else if (const int head = bone_node[idx(bone::head)]; head >= 0) {
        // The spec's: the target's model-space position seen from the head, in the head's
        // normalised frame (forward +Z); the rotation from +Z to it, without roll.
        const glm::dvec3 d = glm::inverse(norm_world[idx(bone::head)]) *
                             (glm::dvec3(world[look_node][3]) - glm::dvec3(world[head][3]));
        const double len = glm::length(d);
        have = true;  // a target on the head itself (or unreadable): looking ahead
        if (len > 1e-9 && std::isfinite(len)) {
          const glm::dvec3 dir = d / len;
          const glm::dvec3 fwd(0.0, 0.0, 1.0);
          const glm::dvec3 axis = glm::cross(fwd, dir);
          const double c = glm::dot(fwd, dir);
          // Half-angle form: q = (1 + c, axis) normalised; straight behind: a turn about Y.
          gaze = c > -1.0 + 1e-12 ? glm::normalize(glm::dquat(1.0 + c, axis.x, axis.y, axis.z))
                                  : glm::dquat(0, 0, 1, 0);
        }
      }
      if (have) {
        if (gaze.w < 0.0) gaze = -gaze;
        const glm::quat q(static_cast<float>(gaze.w), static_cast<float>(gaze.x),
                          static_cast<float>(gaze.y), static_cast<float>(gaze.z));
        for (bone eye : {bone::left_eye, bone::right_eye}) {
          pose[eye] = q;
          pose.confidence[idx(eye)] = 1.f;
        }
        clip.has_look_at = true;
      }
    }
  }
  out = std::move(clip);
  return {};
}

}  // namespace

status read_vrma(const std::string& path, vrma_clip& out, const vrma_read_options& options) {
  try {
    return read_impl(path, out, options);
  } catch (const std::exception& e) {
    return status::internal(path + ": " + e.what());
  } catch (...) {
    return status::internal(path + ": unexpected error while reading");
  }
}

}  // namespace avatarmap
