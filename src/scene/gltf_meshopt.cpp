// EXT_meshopt_compression (gltf_meshopt.hpp): the checks the extension's specification asks
// for, then libmeshoptimizer's decoders and filters.
#include "scene/gltf_meshopt.hpp"

#include "scene/gltf_accessors.hpp"

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <climits>
#include <vector>

namespace covrast::detail {
namespace {

/// The fields of one view's extension object, checked.
struct CompressedView {
  int buffer = 0;
  std::size_t offset = 0;
  std::size_t length = 0;
  std::size_t stride = 0;
  std::size_t count = 0;
  std::string mode;
  std::string filter = "NONE";
};

CompressedView read_fields(const tinygltf::Model& model, const tinygltf::Value& ext,
                           const std::string& name, const std::string& where) {
  const auto fail = [&](const std::string& field, const std::string& why) {
    throw InputError(name + ": " + where + "." + field + ": " + why);
  };
  if (!ext.IsObject()) throw InputError(name + ": " + where + ": expected an object");
  const auto whole = [&](const char* field, int lo, int hi, bool required) -> int {
    if (!ext.Has(field)) {
      if (required) fail(field, "missing");
      return 0;
    }
    const std::optional<int> value = whole_number(ext.Get(field), lo, hi);
    if (!value) {
      fail(field,
           "expected a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    }
    return *value;
  };
  CompressedView v;
  v.buffer = whole("buffer", 0, int(model.buffers.size()) - 1, true);
  v.offset = std::size_t(whole("byteOffset", 0, INT_MAX, false));
  v.length = std::size_t(whole("byteLength", 0, INT_MAX, true));
  v.stride = std::size_t(whole("byteStride", 1, 256, true));
  v.count = std::size_t(whole("count", 0, int(covrast::kMaxAccessorElements), true));
  const auto text = [&](const char* field, bool required) -> std::string {
    if (!ext.Has(field)) {
      if (required) fail(field, "missing");
      return {};
    }
    if (!ext.Get(field).IsString()) fail(field, "expected a string");
    return ext.Get(field).Get<std::string>();
  };
  v.mode = text("mode", true);
  if (ext.Has("filter")) v.filter = text("filter", false);
  if (v.mode == "ATTRIBUTES") {
    if (v.stride % 4 != 0) fail("byteStride", "must be a multiple of 4 for ATTRIBUTES");
  } else if (v.mode == "TRIANGLES" || v.mode == "INDICES") {
    if (v.stride != 2 && v.stride != 4) fail("byteStride", "must be 2 or 4 for " + v.mode);
    if (v.mode == "TRIANGLES" && v.count % 3 != 0) fail("count", "must be a multiple of 3");
  } else {
    fail("mode", "expected ATTRIBUTES, TRIANGLES or INDICES, not '" + printable(v.mode) + "'");
  }
  if (v.filter != "NONE") {
    if (v.mode != "ATTRIBUTES") fail("filter", "only ATTRIBUTES take a filter");
    if (v.filter == "OCTAHEDRAL") {
      if (v.stride != 4 && v.stride != 8) fail("byteStride", "must be 4 or 8 for OCTAHEDRAL");
    } else if (v.filter == "QUATERNION") {
      if (v.stride != 8) fail("byteStride", "must be 8 for QUATERNION");
    } else if (v.filter != "EXPONENTIAL") {
      fail("filter", "expected NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL, not '" +
                         printable(v.filter) + "'");
    }
  }
  const std::vector<unsigned char>& data = model.buffers[std::size_t(v.buffer)].data;
  if (v.offset > data.size() || v.length > data.size() - v.offset) {
    fail("byteLength", "the compressed bytes [" + std::to_string(v.offset) + ", " +
                           std::to_string(v.offset + v.length) + ") exceed buffer " +
                           std::to_string(v.buffer) + " (" + std::to_string(data.size()) +
                           " bytes)");
  }
  return v;
}

/// The decoded bytes of one view.
std::vector<unsigned char> decode(const tinygltf::Model& model, const CompressedView& v,
                                  const std::string& name, const std::string& where) {
  std::vector<unsigned char> out(v.count * v.stride);
  const unsigned char* source = model.buffers[std::size_t(v.buffer)].data.data() + v.offset;
  int status = 0;
  if (v.mode == "ATTRIBUTES") {
    status = meshopt_decodeVertexBuffer(out.data(), v.count, v.stride, source, v.length);
  } else if (v.mode == "TRIANGLES") {
    status = meshopt_decodeIndexBuffer(out.data(), v.count, v.stride, source, v.length);
  } else {
    status = meshopt_decodeIndexSequence(out.data(), v.count, v.stride, source, v.length);
  }
  if (status != 0) {
    throw InputError(name + ": " + where + ": cannot decode the compressed data (meshoptimizer " +
                     "status " + std::to_string(status) + ")");
  }
  if (v.filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), v.count, v.stride);
  if (v.filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), v.count, v.stride);
  if (v.filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), v.count, v.stride);
  return out;
}

}  // namespace

bool empty_meshopt_fallback_buffers(nlohmann::json& document) {
  const auto buffers = document.find("buffers");
  if (buffers == document.end() || !buffers->is_array()) return false;
  bool changed = false;
  for (nlohmann::json& buffer : *buffers) {
    if (!buffer.is_object() || buffer.contains("uri")) continue;
    const auto extensions = buffer.find("extensions");
    if (extensions == buffer.end() || !extensions->is_object()) continue;
    const auto ext = extensions->find(kMeshoptExtension);
    if (ext == extensions->end() || !ext->is_object() || ext->value("fallback", false) != true) {
      continue;
    }
    buffer["uri"] = "data:application/octet-stream;base64,AA==";  // one zero byte
    buffer["byteLength"] = 1;
    changed = true;
  }
  return changed;
}

void decode_meshopt_views(tinygltf::Model& model, const std::string& name) {
  std::uint64_t decoded_bytes = 0;
  for (std::size_t i = 0; i < model.bufferViews.size(); ++i) {
    tinygltf::BufferView& view = model.bufferViews[i];
    const auto it = view.extensions.find(std::string(kMeshoptExtension));
    if (it == view.extensions.end()) continue;
    const std::string where =
        "bufferViews[" + std::to_string(i) + "].extensions." + std::string(kMeshoptExtension);
    const CompressedView v = read_fields(model, it->second, name, where);
    // The decoded view must be what the view says it is: count elements of byteStride bytes.
    if (std::uint64_t(v.count) * v.stride != view.byteLength) {
      throw InputError(name + ": " + where +
                       ": count x byteStride = " + std::to_string(v.count * v.stride) +
                       " bytes, but the view's byteLength is " + std::to_string(view.byteLength));
    }
    decoded_bytes += std::uint64_t(v.count) * v.stride;
    if (decoded_bytes > kMaxMeshoptDecodedBytes) {
      throw InputError(name + ": " + where + ": the decoded views take the file past " +
                       std::to_string(kMaxMeshoptDecodedBytes) + " bytes (docs/limits.md)");
    }
    tinygltf::Buffer buffer;
    buffer.data = decode(model, v, name, where);
    model.buffers.push_back(std::move(buffer));
    view.buffer = int(model.buffers.size()) - 1;
    view.byteOffset = 0;
    // The view keeps its own byteStride, which the accessors read with (the specification
    // asks it to equal the extension's; the reader's bounds hold either way).
    view.extensions.erase(it);
  }
}

}  // namespace covrast::detail
