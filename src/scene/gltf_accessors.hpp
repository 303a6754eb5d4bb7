// glTF accessors and buffer views read for the glTF loader (mesh_gltf.cpp, gltf_pose.cpp):
// every buffer access is bounds-checked here rather than trusted, so that a broken file is an
// InputError and never a crash. Values come out as doubles; normalized integers map to [0, 1]
// or [-1, 1] (glTF 2.0 spec, 3.11).
#pragma once

#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace covrast::detail {

/// Most elements an accessor may hold, and most vertices of one file: indices are 32-bit.
inline constexpr std::size_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();

/// Throws InputError("name: message").
[[noreturn]] void fail(const std::string& name, const std::string& message);

/// `text` with every byte outside printable ASCII shown as '?' (messages are one line).
std::string printable(std::string text);

/// A JSON number of the file (a tinygltf Value, integer or real) as a whole number in
/// [lo, hi], or nullopt when it is not a number, not whole, or outside: compared as a double
/// before it is converted, since a double outside int's range converted to int is undefined
/// (a KHR_texture_transform texCoord of 1e30 was).
std::optional<int> whole_number(const tinygltf::Value& value, int lo, int hi);

/// A number for a message: as short as it prints ("3", "1e+30", "-1.5").
std::string number_text(double value);

/// A factor of the file clamped to [0, 1] as a float (NaN becomes 0).
inline float clamp_unit(double value) {
  if (!(value > 0.0)) return 0.0f;  // also NaN
  return value >= 1.0 ? 1.0f : static_cast<float>(value);
}

/// The accessors of `model`, read for messages that start with `name` (the file).
struct GltfReader {
  const tinygltf::Model& model;
  const std::string& name;

  /// The first byte of buffer view `view_index`, checked to lie with its byteLength bytes
  /// inside its buffer.
  const unsigned char* view_bytes(const std::string& what, int view_index) const;

  /// Reads `count` elements of `components` components from a buffer view into `out`.
  /// `strided`: honour the view's byteStride (vertex attributes), else tightly packed.
  void read_view(const std::string& what, int view_index, std::size_t byte_offset,
                 std::size_t count, int component_type, int components, bool normalized,
                 bool strided, double* out) const;

  /// Reads a whole accessor (including sparse substitution) as doubles, `components` per
  /// element; `components` receives the element width.
  std::vector<double> read_accessor(const std::string& what, int accessor_index,
                                    int& components) const;
};

}  // namespace covrast::detail
