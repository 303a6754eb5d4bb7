// The JSON edits before tinygltf (gltf_rewrite.hpp).
#include "scene/gltf_rewrite.hpp"

#include "scene/gltf_draco.hpp"
#include "scene/gltf_meshopt.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>

namespace covrast::detail {
namespace {

using nlohmann::json;

constexpr std::uint32_t kGlbJsonChunk = 0x4E4F534Au;  // "JSON"
constexpr std::size_t kGlbHeaderBytes = 12;           // magic, version, length
constexpr std::size_t kGlbChunkHeaderBytes = 8;       // length, type

std::uint32_t load_u32(const char* bytes) {
  std::uint32_t value;
  std::memcpy(&value, bytes, 4);
  return value;
}

void append_u32(std::string& out, std::uint32_t value) {
  char bytes[4];
  std::memcpy(bytes, &value, 4);
  out.append(bytes, 4);
}

/// The JSON text edited, or nullopt (no change, or no valid JSON).
std::optional<std::string> rewrite_json(std::string_view text) {
  json document = json::parse(text, nullptr, false);
  if (document.is_discarded() || !document.is_object()) return std::nullopt;
  const bool draco = strip_draco_indices(document);
  const bool meshopt = empty_meshopt_fallback_buffers(document);
  if (!draco && !meshopt) return std::nullopt;
  return document.dump();
}

/// A .glb with its JSON chunk rewritten; the chunks after it are kept byte for byte.
std::optional<std::string> rewrite_glb(std::string_view bytes) {
  if (bytes.size() < kGlbHeaderBytes + kGlbChunkHeaderBytes) return std::nullopt;
  const std::uint32_t json_length = load_u32(bytes.data() + kGlbHeaderBytes);
  const std::uint32_t chunk_type = load_u32(bytes.data() + kGlbHeaderBytes + 4);
  const std::size_t json_begin = kGlbHeaderBytes + kGlbChunkHeaderBytes;
  if (chunk_type != kGlbJsonChunk || json_length > bytes.size() - json_begin) return std::nullopt;
  std::optional<std::string> text = rewrite_json(bytes.substr(json_begin, json_length));
  if (!text) return std::nullopt;
  while (text->size() % 4 != 0) *text += ' ';  // chunks stay 4-byte aligned
  const std::string_view rest = bytes.substr(json_begin + json_length);
  std::string out(bytes.substr(0, 8));  // magic and version
  append_u32(out, static_cast<std::uint32_t>(json_begin + text->size() + rest.size()));
  append_u32(out, static_cast<std::uint32_t>(text->size()));
  append_u32(out, kGlbJsonChunk);
  out += *text;
  out += rest;
  return out;
}

}  // namespace

std::optional<std::string> rewritten_for_tinygltf(std::string_view bytes) {
  if (bytes.find(kDracoExtension) == std::string_view::npos &&
      bytes.find(kMeshoptExtension) == std::string_view::npos) {
    return std::nullopt;
  }
  return bytes.substr(0, 4) == "glTF" ? rewrite_glb(bytes) : rewrite_json(bytes);
}

}  // namespace covrast::detail
