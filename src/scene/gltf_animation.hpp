// Posing a glTF file at a moment of one of its animations (glTF 2.0, 3.11 and Appendix C): each
// channel's sampler is evaluated at the time and written into its node's translation, rotation,
// scale or morph weights, before the node walk (mesh_gltf.cpp) composes transforms, poses skins
// by their joints and applies the weights, exactly as for the static pose.
#pragma once

#include <covrast/scene.hpp>

#include <tiny_gltf.h>

#include <string>
#include <vector>

namespace covrast::detail {

/// Samples the requested animation (AnimationTime: by index, else by name, else the first) at
/// its time into `model`'s nodes. Times before the first
/// keyframe take the first value, after the last the last. Interpolation: STEP (the value of
/// the keyframe at or before), LINEAR (spherical for rotations, along the shorter arc) and
/// CUBICSPLINE (the Hermite spline of the specification's Appendix C, with its tangents
/// scaled by the keyframe interval; rotations normalised). A file without animations gets a
/// warning in `warnings` and keeps its static pose; an unknown animation, broken samplers or
/// accessors are errors (InputError naming `name`).
void pose_at_time(tinygltf::Model& model, const std::string& name, const AnimationTime& request,
                  std::vector<std::string>& warnings);

}  // namespace covrast::detail
