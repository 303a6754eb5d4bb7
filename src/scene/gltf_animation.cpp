// Sampling glTF animations (formulas in scene/gltf_animation.hpp).
#include "scene/gltf_animation.hpp"

#include "scene/gltf_accessors.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace covrast::detail {
namespace {

enum class Interpolation { Step, Linear, CubicSpline };

/// One sampler, read: keyframe times and per keyframe `width` values (three groups of them
/// per keyframe for CUBICSPLINE: in-tangent, value, out-tangent).
struct Sampler {
  std::vector<double> times;
  std::vector<double> values;
  std::size_t width = 0;
  Interpolation interpolation = Interpolation::Linear;
};

Interpolation interpolation_of(const std::string& text, const std::string& name,
                               const std::string& what) {
  if (text.empty() || text == "LINEAR") return Interpolation::Linear;
  if (text == "STEP") return Interpolation::Step;
  if (text == "CUBICSPLINE") return Interpolation::CubicSpline;
  fail(name, what + ": unknown interpolation '" + printable(text) + "'");
}

Sampler read_sampler(const GltfReader& reader, const tinygltf::AnimationSampler& source,
                     std::size_t width, const std::string& what) {
  Sampler sampler;
  sampler.width = width;
  sampler.interpolation = interpolation_of(source.interpolation, reader.name, what);
  int components = 0;
  sampler.times = reader.read_accessor(what + " input", source.input, components);
  if (components != 1) fail(reader.name, what + ": input must be SCALAR times");
  if (sampler.times.empty()) fail(reader.name, what + ": no keyframes");
  for (std::size_t k = 0; k < sampler.times.size(); ++k) {
    if (!std::isfinite(sampler.times[k]) || (k > 0 && !(sampler.times[k] > sampler.times[k - 1]))) {
      fail(reader.name, what + ": keyframe times must be finite and strictly increasing");
    }
  }
  sampler.values = reader.read_accessor(what + " output", source.output, components);
  const std::size_t groups = sampler.interpolation == Interpolation::CubicSpline ? 3 : 1;
  if (sampler.values.size() != sampler.times.size() * groups * width) {
    fail(reader.name, what + ": output has " + std::to_string(sampler.values.size()) +
                          " numbers, expected " + std::to_string(sampler.times.size()) +
                          " keyframes x " + std::to_string(groups * width));
  }
  return sampler;
}

/// The `width` numbers of keyframe k's value (group 1 of 3 for CUBICSPLINE).
const double* key_value(const Sampler& s, std::size_t k, int group = 1) {
  const std::size_t groups = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  const std::size_t at = groups == 3 ? k * 3 + std::size_t(group) : k;
  return &s.values[at * s.width];
}

/// Unit quaternion on the shorter arc from a to b at fraction u (slerp; lerp when they are
/// nearly parallel).
std::vector<double> slerp(const double* a, const double* b, double u) {
  double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
  const double sign = dot < 0.0 ? -1.0 : 1.0;
  dot *= sign;
  double wa = 1.0 - u, wb = u * sign;
  if (dot < 0.9995) {
    const double theta = std::acos(std::min(dot, 1.0));
    const double sin_theta = std::sin(theta);
    wa = std::sin((1.0 - u) * theta) / sin_theta;
    wb = std::sin(u * theta) / sin_theta * sign;
  }
  std::vector<double> q(4);
  for (int c = 0; c < 4; ++c) q[std::size_t(c)] = wa * a[c] + wb * b[c];
  return q;
}

void normalize(std::vector<double>& q) {
  const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (length > 0.0) {
    for (double& x : q) x /= length;
  }
}

/// The sampler's value at time t (rotation: a quaternion, normalised).
std::vector<double> sample(const Sampler& s, double t, bool rotation) {
  const std::size_t last = s.times.size() - 1;
  if (!(t > s.times[0]) || last == 0) return {key_value(s, 0), key_value(s, 0) + s.width};
  if (t >= s.times[last]) return {key_value(s, last), key_value(s, last) + s.width};
  // The keyframe k with t_k <= t < t_{k+1}.
  const std::size_t k =
      std::size_t(std::upper_bound(s.times.begin(), s.times.end(), t) - s.times.begin()) - 1;
  const double t0 = s.times[k], t1 = s.times[k + 1], interval = t1 - t0;
  const double u = (t - t0) / interval;
  const double* v0 = key_value(s, k);
  const double* v1 = key_value(s, k + 1);
  std::vector<double> out(s.width);
  if (s.interpolation == Interpolation::Step) {
    out.assign(v0, v0 + s.width);
  } else if (s.interpolation == Interpolation::Linear) {
    if (rotation) return slerp(v0, v1, u);
    for (std::size_t c = 0; c < s.width; ++c) out[c] = v0[c] + (v1[c] - v0[c]) * u;
  } else {
    // Appendix C: p(u) = (2u^3 - 3u^2 + 1) v_k + td (u^3 - 2u^2 + u) b_k
    //                  + (-2u^3 + 3u^2) v_k+1 + td (u^3 - u^2) a_k+1.
    const double* b0 = key_value(s, k, 2);
    const double* a1 = key_value(s, k + 1, 0);
    const double u2 = u * u, u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
                 h11 = u3 - u2;
    for (std::size_t c = 0; c < s.width; ++c) {
      out[c] = h00 * v0[c] + interval * h10 * b0[c] + h01 * v1[c] + interval * h11 * a1[c];
    }
  }
  if (rotation) normalize(out);
  return out;
}

/// The number of morph targets of node `node`'s mesh (its first primitive's).
std::size_t morph_target_count(const tinygltf::Model& model, const tinygltf::Node& node) {
  if (node.mesh < 0 || std::size_t(node.mesh) >= model.meshes.size()) return 0;
  const tinygltf::Mesh& mesh = model.meshes[std::size_t(node.mesh)];
  return mesh.primitives.empty() ? 0 : mesh.primitives.front().targets.size();
}

int select_animation(const tinygltf::Model& model, const std::string& name,
                     const AnimationTime& request) {
  const int count = int(model.animations.size());
  if (request.index >= 0) {
    if (request.index >= count) {
      fail(name, "animation " + std::to_string(request.index) + " does not exist (the file has " +
                     std::to_string(count) + ")");
    }
    return request.index;
  }
  if (request.name.empty()) return 0;
  for (int i = 0; i < count; ++i) {
    if (model.animations[std::size_t(i)].name == request.name) return i;
  }
  std::string names;
  for (const tinygltf::Animation& a : model.animations) {
    names += (names.empty() ? "'" : ", '") + printable(a.name) + "'";
  }
  fail(name, "no animation named '" + printable(request.name) + "' (the file has " +
                 (names.empty() ? std::string("none") : names) + ")");
}

}  // namespace

void pose_at_time(tinygltf::Model& model, const std::string& name, const AnimationTime& request,
                  std::vector<std::string>& warnings) {
  if (!std::isfinite(request.time_s) || request.time_s < 0.0) {
    fail(name, "animation time must be a finite number of seconds >= 0");
  }
  if (model.animations.empty()) {
    warnings.push_back(name +
                       ": an animation time was given but the file has no animations: "
                       "the static pose is drawn");
    return;
  }
  const int selected = select_animation(model, name, request);
  const tinygltf::Animation& animation = model.animations[std::size_t(selected)];
  const GltfReader reader{model, name};
  for (std::size_t c = 0; c < animation.channels.size(); ++c) {
    const tinygltf::AnimationChannel& channel = animation.channels[c];
    const std::string what =
        "animation " + std::to_string(selected) + " channel " + std::to_string(c);
    if (channel.target_node < 0) continue;  // no node: the channel may target an extension
    if (std::size_t(channel.target_node) >= model.nodes.size()) {
      fail(name, what + ": node " + std::to_string(channel.target_node) + " does not exist");
    }
    if (channel.sampler < 0 || std::size_t(channel.sampler) >= animation.samplers.size()) {
      fail(name, what + ": sampler " + std::to_string(channel.sampler) + " does not exist");
    }
    tinygltf::Node& node = model.nodes[std::size_t(channel.target_node)];
    if (!node.matrix.empty()) {
      fail(name, what + ": node " + std::to_string(channel.target_node) +
                     " has a matrix, which an animation may not target (glTF 2.0, 3.5.3)");
    }
    const tinygltf::AnimationSampler& source = animation.samplers[std::size_t(channel.sampler)];
    const std::string& path = channel.target_path;
    if (path == "translation" || path == "scale") {
      node.*(path == "translation" ? &tinygltf::Node::translation : &tinygltf::Node::scale) =
          sample(read_sampler(reader, source, 3, what), request.time_s, false);
    } else if (path == "rotation") {
      node.rotation = sample(read_sampler(reader, source, 4, what), request.time_s, true);
    } else if (path == "weights") {
      const std::size_t targets = morph_target_count(model, node);
      if (targets == 0) fail(name, what + ": weights for a node whose mesh has no morph targets");
      node.weights = sample(read_sampler(reader, source, targets, what), request.time_s, false);
    } else {
      warnings.push_back(name + ": " + what + ": target path '" + printable(path) +
                         "' is not animated by covrast");
    }
  }
}

}  // namespace covrast::detail
