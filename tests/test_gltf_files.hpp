// Tests: writing small glTF files by hand (little-endian packing, base64 data: URIs, the .glb
// container) and GltfBuilder, which appends typed arrays to one buffer as accessors.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace covrast::test {

inline void put_f32(std::string& out, float value) {
  char bytes[4];
  std::memcpy(bytes, &value, 4);
  out.append(bytes, 4);
}
inline void put_u32(std::string& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((value >> (8 * i)) & 255u);
}
inline void put_u16(std::string& out, std::uint16_t value) {
  out += static_cast<char>(value & 255u);
  out += static_cast<char>(value >> 8);
}
inline void put_u8(std::string& out, std::uint8_t value) { out += static_cast<char>(value); }

inline std::string base64(const std::string& data) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const std::uint32_t n = (std::uint32_t(std::uint8_t(data[i])) << 16) |
                            (std::uint32_t(std::uint8_t(data[i + 1])) << 8) |
                            std::uint32_t(std::uint8_t(data[i + 2]));
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += kAlphabet[n & 63];
  }
  if (i + 1 == data.size()) {
    const std::uint32_t n = std::uint32_t(std::uint8_t(data[i])) << 16;
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += "==";
  } else if (i + 2 == data.size()) {
    const std::uint32_t n = (std::uint32_t(std::uint8_t(data[i])) << 16) |
                            (std::uint32_t(std::uint8_t(data[i + 1])) << 8);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += '=';
  }
  return out;
}

/// Binary glTF container: 12-byte header, JSON chunk (space padded), BIN chunk (zero padded).
inline std::string make_glb(std::string json_text, std::string bin) {
  while (json_text.size() % 4 != 0) json_text += ' ';
  while (bin.size() % 4 != 0) bin += '\0';
  std::string out = "glTF";
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json_text.size() + 8 + bin.size()));
  put_u32(out, static_cast<std::uint32_t>(json_text.size()));
  put_u32(out, 0x4E4F534Au);  // "JSON"
  out += json_text;
  put_u32(out, static_cast<std::uint32_t>(bin.size()));
  put_u32(out, 0x004E4942u);  // "BIN\0"
  out += bin;
  return out;
}

/// A glTF document with one binary buffer: each add_* call appends a 4-byte aligned buffer
/// view and an accessor over it and returns the accessor's index. `gltf` is filled in by the
/// test (nodes, meshes, ...); glb() and gltf_text() write the whole file.
class GltfBuilder {
 public:
  nlohmann::json gltf = {{"asset", {{"version", "2.0"}}}};

  /// Floats, `type` "SCALAR", "VEC3", "VEC4" or "MAT4" (count = values / width).
  int add_floats(const std::vector<float>& values, const std::string& type) {
    std::string bytes;
    for (const float v : values) put_f32(bytes, v);
    return add_accessor(bytes, 5126, type, values.size() / width(type), false);
  }
  /// Unsigned shorts (indices, JOINTS_0).
  int add_u16(const std::vector<std::uint16_t>& values, const std::string& type) {
    std::string bytes;
    for (const std::uint16_t v : values) put_u16(bytes, v);
    return add_accessor(bytes, 5123, type, values.size() / width(type), false);
  }
  /// Signed shorts, `normalized` or not (KHR_mesh_quantization positions).
  int add_i16(const std::vector<std::int16_t>& values, const std::string& type, bool normalized) {
    std::string bytes;
    for (const std::int16_t v : values) put_u16(bytes, static_cast<std::uint16_t>(v));
    return add_accessor(bytes, 5122, type, values.size() / width(type), normalized);
  }
  /// Raw bytes as a buffer view of their own (no accessor); returns the view's index.
  int add_view(const std::string& bytes) {
    while (bin_.size() % 4 != 0) bin_ += '\0';
    const std::size_t offset = bin_.size();
    bin_ += bytes;
    gltf["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes.size()}});
    return static_cast<int>(gltf["bufferViews"].size()) - 1;
  }
  /// One node holding mesh 0 in scene 0, and that mesh with `primitives`.
  void single_mesh(const nlohmann::json& primitives) {
    gltf["scenes"] = {{{"nodes", {0}}}};
    gltf["nodes"] = {{{"mesh", 0}}};
    gltf["meshes"] = {{{"primitives", primitives}}};
  }
  /// The document as .gltf text, its buffer inlined as a base64 data: URI.
  std::string gltf_text() const {
    nlohmann::json document = gltf;
    document["buffers"] = {{{"byteLength", bin_.size()},
                            {"uri", "data:application/octet-stream;base64," + base64(bin_)}}};
    return document.dump();
  }
  std::string glb() const {
    nlohmann::json document = gltf;
    document["buffers"] = {{{"byteLength", bin_.size()}}};
    return make_glb(document.dump(), bin_);
  }

 private:
  static std::size_t width(const std::string& type) {
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4") return 4;
    if (type == "MAT4") return 16;
    return 1;
  }
  int add_accessor(const std::string& bytes, int component_type, const std::string& type,
                   std::size_t count, bool normalized) {
    const int view = add_view(bytes);
    nlohmann::json accessor = {
        {"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (normalized) accessor["normalized"] = true;
    gltf["accessors"].push_back(accessor);
    return static_cast<int>(gltf["accessors"].size()) - 1;
  }

  std::string bin_;
};

}  // namespace covrast::test
