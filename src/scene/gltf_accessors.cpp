// glTF accessor reading (gltf_accessors.hpp): bounds checks, component conversion, sparse
// substitution.
#include "scene/gltf_accessors.hpp"

#include <covrast/error.hpp>
#include <covrast/scene.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

namespace covrast::detail {
namespace {

static_assert(std::endian::native == std::endian::little, "glTF buffers are little-endian");

int component_size_bytes(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

template <typename T>
T load(const unsigned char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof value);
  return value;
}

/// One component; normalized integers map to [0, 1] or [-1, 1] (glTF 2.0 spec, 3.11).
double read_component(const unsigned char* bytes, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = load<std::int8_t>(bytes);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const double v = load<std::uint8_t>(bytes);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = load<std::int16_t>(bytes);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = load<std::uint16_t>(bytes);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return load<std::uint32_t>(bytes);
    default:
      return load<float>(bytes);
  }
}

}  // namespace

void fail(const std::string& name, const std::string& message) {
  throw InputError(name + ": " + message);
}

std::optional<int> whole_number(const tinygltf::Value& value, int lo, int hi) {
  if (!value.IsNumber()) return std::nullopt;
  const double x = value.GetNumberAsDouble();
  if (!(x >= double(lo) && x <= double(hi)) || std::floor(x) != x) return std::nullopt;
  return static_cast<int>(x);
}

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

/// `text` with every byte outside printable ASCII shown as '?' (messages are one line).
std::string printable(std::string text) {
  for (char& c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte >= 0x7f) c = '?';
  }
  return text;
}

const unsigned char* GltfReader::view_bytes(const std::string& what, int view_index) const {
  if (view_index < 0 || static_cast<std::size_t>(view_index) >= model.bufferViews.size()) {
    fail(name, what + ": bufferView " + std::to_string(view_index) + " does not exist");
  }
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(view_index)];
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) {
    fail(name, what + ": buffer " + std::to_string(view.buffer) + " does not exist");
  }
  const std::vector<unsigned char>& data =
      model.buffers[static_cast<std::size_t>(view.buffer)].data;
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
    fail(name, what + ": bufferView " + std::to_string(view_index) + " exceeds its buffer");
  }
  return data.data() + view.byteOffset;
}

void GltfReader::read_view(const std::string& what, int view_index, std::size_t byte_offset,
                           std::size_t count, int component_type, int components, bool normalized,
                           bool strided, double* out) const {
  const unsigned char* view_begin = view_bytes(what, view_index);
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(view_index)];
  if (count == 0) return;
  const std::size_t element_bytes = static_cast<std::size_t>(component_size_bytes(component_type)) *
                                    static_cast<std::size_t>(components);
  const std::size_t stride = strided && view.byteStride != 0 ? view.byteStride : element_bytes;
  if (stride < element_bytes) fail(name, what + ": byteStride smaller than one element");
  // Last element must end inside the view: offset + stride * (count - 1) + element <= length.
  if (byte_offset > view.byteLength || view.byteLength - byte_offset < element_bytes ||
      count - 1 > (view.byteLength - byte_offset - element_bytes) / stride) {
    fail(name, what + ": accessor reads past the end of bufferView " + std::to_string(view_index));
  }
  const unsigned char* base = view_begin + byte_offset;
  const std::size_t size = static_cast<std::size_t>(component_size_bytes(component_type));
  for (std::size_t i = 0; i < count; ++i) {
    for (int c = 0; c < components; ++c) {
      out[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] = read_component(
          base + i * stride + static_cast<std::size_t>(c) * size, component_type, normalized);
    }
  }
}

std::vector<double> GltfReader::read_accessor(const std::string& what, int accessor_index,
                                              int& components) const {
  if (accessor_index < 0 || static_cast<std::size_t>(accessor_index) >= model.accessors.size()) {
    fail(name, what + ": accessor " + std::to_string(accessor_index) + " does not exist");
  }
  const tinygltf::Accessor& accessor = model.accessors[static_cast<std::size_t>(accessor_index)];
  components = component_count(accessor.type);
  if (components == 0 || component_size_bytes(accessor.componentType) == 0) {
    fail(name, what + ": unsupported accessor type or component type");
  }
  const auto width = static_cast<std::size_t>(components);
  // Before allocating: an accessor without a bufferView is all zeros and costs no file bytes.
  if (accessor.count > kMaxAccessorElements) {
    fail(name, what + ": accessor " + std::to_string(accessor_index) + " has " +
                   std::to_string(accessor.count) + " elements, more than the " +
                   std::to_string(kMaxAccessorElements) + " covrast reads (docs/limits.md)");
  }
  std::vector<double> values;
  if (accessor.bufferView >= 0) {
    // Validate the view before allocating: it must hold count elements of >= 1 byte.
    read_view(what, accessor.bufferView, accessor.byteOffset, 0, accessor.componentType, components,
              accessor.normalized, true, nullptr);
    const tinygltf::BufferView& view =
        model.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
    if (accessor.count > view.byteLength) {
      fail(name, what + ": accessor reads past the end of bufferView " +
                     std::to_string(accessor.bufferView));
    }
    values.resize(accessor.count * width);
    read_view(what, accessor.bufferView, accessor.byteOffset, accessor.count,
              accessor.componentType, components, accessor.normalized, true, values.data());
  } else {
    values.assign(accessor.count * width, 0.0);
  }
  if (accessor.sparse.isSparse) {
    const auto& sparse = accessor.sparse;
    if (sparse.count < 0 || static_cast<std::size_t>(sparse.count) > accessor.count ||
        sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0) {
      fail(name, what + ": bad sparse accessor");
    }
    const int index_type = sparse.indices.componentType;
    if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      fail(name, what + ": bad sparse index component type");
    }
    const auto sparse_count = static_cast<std::size_t>(sparse.count);
    std::vector<double> targets(sparse_count);
    std::vector<double> replacements(sparse_count * width);
    read_view(what + " (sparse indices)", sparse.indices.bufferView,
              static_cast<std::size_t>(sparse.indices.byteOffset), sparse_count, index_type, 1,
              false, false, targets.data());
    read_view(what + " (sparse values)", sparse.values.bufferView,
              static_cast<std::size_t>(sparse.values.byteOffset), sparse_count,
              accessor.componentType, components, accessor.normalized, false, replacements.data());
    for (std::size_t i = 0; i < sparse_count; ++i) {
      const auto target = static_cast<std::size_t>(targets[i]);
      if (target >= accessor.count) fail(name, what + ": sparse index out of range");
      // glTF 2.0, 3.6.2.3: the indices strictly increase (issue 28: unsorted ones were taken).
      if (i > 0 && !(targets[i] > targets[i - 1])) {
        fail(name, what + ": sparse indices must strictly increase (" +
                       number_text(targets[i - 1]) + " then " + number_text(targets[i]) + ")");
      }
      std::copy_n(replacements.begin() + static_cast<std::ptrdiff_t>(i * width), width,
                  values.begin() + static_cast<std::ptrdiff_t>(target * width));
    }
  }
  return values;
}

}  // namespace covrast::detail
