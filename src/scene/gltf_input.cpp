// Checks on a glTF file before tinygltf reads it (gltf_input.hpp). tinygltf skips a field of
// the wrong JSON type without a word (a file then loads as 0 triangles), recurses once per
// nesting level of `extras`, and words buffer problems as "File not found : data:..." or
// "Failed to decode 'uri'"; here each of these is an InputError naming the field.
#include "scene/gltf_input.hpp"

#include "scene/gltf_accessors.hpp"
#include "scene/scene_internal.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <system_error>

namespace covrast::detail {
namespace {

using nlohmann::json;

/// What a field of a glTF object must be (glTF 2.0 JSON schema, for the fields covrast reads).
/// Name: a string whose wrong type is a warning, not an error, as covrast does not use it.
enum class Kind {
  Index,
  Count,
  Integer,
  Number,
  String,
  Name,
  Bool,
  Object,
  Array,
  IndexArray,
  NumberArray
};

struct Field {
  const char* key;
  Kind kind;
  /// NumberArray: the number of elements the schema requires (0: any).
  std::size_t length = 0;
  /// Object: the fields of the object, checked the same way (null: none).
  const std::vector<Field>* fields = nullptr;
};

/// textureInfo, normalTextureInfo and occlusionTextureInfo (glTF 2.0, 5.22-5.24).
const std::vector<Field> kTextureInfoFields = {{"index", Kind::Index},
                                               {"texCoord", Kind::Count},
                                               {"scale", Kind::Number},
                                               {"strength", Kind::Number},
                                               {"extensions", Kind::Object}};
/// material.pbrMetallicRoughness (glTF 2.0, 5.19).
const std::vector<Field> kPbrFields = {
    {"baseColorFactor", Kind::NumberArray, 4},
    {"metallicFactor", Kind::Number},
    {"roughnessFactor", Kind::Number},
    {"baseColorTexture", Kind::Object, 0, &kTextureInfoFields},
    {"metallicRoughnessTexture", Kind::Object, 0, &kTextureInfoFields}};

/// material.extensions: the material extensions covrast reads are objects (their fields are
/// checked where they are read, scene/gltf_materials.cpp).
const std::vector<Field> kMaterialExtensionFields = {
    {"KHR_materials_ior", Kind::Object},          {"KHR_materials_specular", Kind::Object},
    {"KHR_materials_clearcoat", Kind::Object},    {"KHR_materials_sheen", Kind::Object},
    {"KHR_materials_iridescence", Kind::Object},  {"KHR_materials_emissive_strength", Kind::Object},
    {"KHR_materials_unlit", Kind::Object},        {"KHR_materials_anisotropy", Kind::Object},
    {"KHR_materials_transmission", Kind::Object}, {"KHR_materials_volume", Kind::Object},
    {"KHR_materials_dispersion", Kind::Object}};

/// The top-level arrays whose elements covrast reads, and the fields it reads of each.
struct Section {
  const char* key;
  std::vector<Field> fields;
};

const std::vector<Section>& sections() {
  static const std::vector<Section> kSections = {
      {"accessors",
       {{"bufferView", Kind::Index},
        {"byteOffset", Kind::Count},
        {"componentType", Kind::Integer},
        {"count", Kind::Count},
        {"type", Kind::String},
        {"normalized", Kind::Bool},
        {"sparse", Kind::Object},
        {"name", Kind::Name}}},
      {"bufferViews",
       {{"buffer", Kind::Index},
        {"byteOffset", Kind::Count},
        {"byteLength", Kind::Count},
        {"byteStride", Kind::Count},
        {"name", Kind::Name}}},
      {"buffers", {{"byteLength", Kind::Count}, {"uri", Kind::String}, {"name", Kind::Name}}},
      {"meshes",
       {{"primitives", Kind::Array}, {"weights", Kind::NumberArray}, {"name", Kind::Name}}},
      {"nodes",
       {{"children", Kind::IndexArray},
        {"mesh", Kind::Index},
        {"camera", Kind::Index},
        {"skin", Kind::Index},
        {"matrix", Kind::NumberArray},
        {"translation", Kind::NumberArray},
        {"rotation", Kind::NumberArray},
        {"scale", Kind::NumberArray},
        {"weights", Kind::NumberArray},
        {"extensions", Kind::Object},
        {"name", Kind::Name}}},
      {"scenes", {{"nodes", Kind::IndexArray}, {"name", Kind::Name}}},
      {"materials",
       {{"pbrMetallicRoughness", Kind::Object, 0, &kPbrFields},
        {"normalTexture", Kind::Object, 0, &kTextureInfoFields},
        {"occlusionTexture", Kind::Object, 0, &kTextureInfoFields},
        {"emissiveTexture", Kind::Object, 0, &kTextureInfoFields},
        {"emissiveFactor", Kind::NumberArray, 3},
        {"alphaMode", Kind::String},
        {"alphaCutoff", Kind::Number},
        {"doubleSided", Kind::Bool},
        {"extensions", Kind::Object, 0, &kMaterialExtensionFields},
        {"name", Kind::Name}}},
      {"cameras", {{"type", Kind::String}, {"name", Kind::Name}}},
      {"skins",
       {{"joints", Kind::IndexArray}, {"inverseBindMatrices", Kind::Index}, {"name", Kind::Name}}},
      {"images",
       {{"uri", Kind::String},
        {"bufferView", Kind::Index},
        {"mimeType", Kind::String},
        {"name", Kind::Name}}},
      {"textures",
       {{"sampler", Kind::Index},
        {"source", Kind::Index},
        {"extensions", Kind::Object},
        {"name", Kind::Name}}},
      {"samplers",
       {{"magFilter", Kind::Integer},
        {"minFilter", Kind::Integer},
        {"wrapS", Kind::Integer},
        {"wrapT", Kind::Integer},
        {"name", Kind::Name}}},
      {"animations", {{"name", Kind::Name}}},
  };
  return kSections;
}

const std::vector<Field>& primitive_fields() {
  static const std::vector<Field> kFields = {{"attributes", Kind::Object},
                                             {"indices", Kind::Index},
                                             {"material", Kind::Index},
                                             {"mode", Kind::Count},
                                             {"targets", Kind::Array}};
  return kFields;
}

/// A JSON value shortened for a one-line message (nesting is bounded before parsing).
std::string shown(const json& value) {
  constexpr std::size_t kMaxShown = 40;
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return printable(text);
}

bool is_index(const json& value) {
  return value.is_number_unsigned() ||
         (value.is_number_integer() && value.get<std::int64_t>() >= 0);
}

bool has_kind(const json& value, Kind kind) {
  switch (kind) {
    case Kind::Index:
    case Kind::Count:
      return is_index(value);
    case Kind::Integer:
      return value.is_number_integer();
    case Kind::Number:
      return value.is_number();
    case Kind::String:
    case Kind::Name:
      return value.is_string();
    case Kind::Bool:
      return value.is_boolean();
    case Kind::Object:
      return value.is_object();
    case Kind::Array:
      return value.is_array();
    case Kind::IndexArray:
      return value.is_array() && std::all_of(value.begin(), value.end(), is_index);
    case Kind::NumberArray:
      return value.is_array() &&
             std::all_of(value.begin(), value.end(), [](const json& v) { return v.is_number(); });
  }
  return false;
}

const char* kind_text(Kind kind) {
  switch (kind) {
    case Kind::Index:
      return "an index (an integer >= 0)";
    case Kind::Count:
      return "an integer >= 0";
    case Kind::Integer:
      return "an integer";
    case Kind::Number:
      return "a number";
    case Kind::String:
    case Kind::Name:
      return "a string";
    case Kind::Bool:
      return "true or false";
    case Kind::Object:
      return "an object";
    case Kind::Array:
      return "an array";
    case Kind::IndexArray:
      return "an array of indices";
    case Kind::NumberArray:
      return "an array of numbers";
  }
  return "";
}

/// What the schema check found: errors (wrong types of fields covrast uses) and warnings (of
/// fields it ignores), each a message starting with the JSON path, in document order.
struct SchemaFindings {
  std::vector<std::string> errors;
  std::vector<std::string> warnings;
};

/// Checks the fields of `object` at JSON path `path`: a wrong type of a field covrast uses is
/// an error; of one it ignores (Kind::Name), a warning. Goes on past each, so that every
/// finding is listed.
void check_fields(const json& object, const std::vector<Field>& fields, const std::string& path,
                  SchemaFindings& found) {
  if (!object.is_object()) {
    found.errors.push_back(path + ": expected an object, got " + shown(object));
    return;
  }
  for (const Field& field : fields) {
    const auto it = object.find(field.key);
    if (it == object.end()) continue;
    const std::string where = path + "." + field.key;
    if (!has_kind(*it, field.kind)) {
      const std::string problem =
          where + ": expected " + kind_text(field.kind) + ", got " + shown(*it);
      (field.kind == Kind::Name ? found.warnings : found.errors).push_back(problem);
      continue;
    }
    if (field.length != 0 && it->size() != field.length) {
      found.errors.push_back(where + ": expected " + std::to_string(field.length) +
                             " numbers, got " + std::to_string(it->size()));
      continue;
    }
    if (field.fields != nullptr) check_fields(*it, *field.fields, where, found);
  }
}

/// The JSON types of every field covrast reads (tinygltf would skip a wrong one silently).
SchemaFindings check_schema(const json& root) {
  SchemaFindings found;
  if (!root.is_object()) {
    found.errors.push_back("expected a JSON object at the top level");
    return found;
  }
  check_fields(root,
               {{"asset", Kind::Object},
                {"scene", Kind::Index},
                {"extensionsUsed", Kind::Array},
                {"extensionsRequired", Kind::Array}},
               "glTF", found);
  for (const Section& section : sections()) {
    const auto it = root.find(section.key);
    if (it == root.end()) continue;
    if (!it->is_array()) {
      found.errors.push_back(std::string(section.key) + ": expected an array, got " + shown(*it));
      continue;
    }
    for (std::size_t i = 0; i < it->size(); ++i) {
      const std::string path = std::string(section.key) + "[" + std::to_string(i) + "]";
      check_fields((*it)[i], section.fields, path, found);
      if (std::strcmp(section.key, "meshes") != 0 || !(*it)[i].is_object()) continue;
      const auto primitives = (*it)[i].find("primitives");
      if (primitives == (*it)[i].end() || !primitives->is_array()) continue;
      for (std::size_t p = 0; p < primitives->size(); ++p) {
        check_fields((*primitives)[p], primitive_fields(),
                     path + ".primitives[" + std::to_string(p) + "]", found);
      }
    }
  }
  return found;
}

/// Bytes that base64 text decodes to as tinygltf decodes it: up to the first byte outside
/// the alphabet (or '='), 3 bytes per 4 characters, 1 or 2 for a final 2 or 3.
std::uint64_t base64_decoded_bytes(std::string_view text) {
  std::uint64_t chars = 0;
  while (chars < text.size() && (std::isalnum(static_cast<unsigned char>(text[chars])) ||
                                 text[chars] == '+' || text[chars] == '/')) {
    ++chars;
  }
  const std::uint64_t tail = chars % 4;
  return chars / 4 * 3 + (tail == 2 ? 1 : tail == 3 ? 2 : 0);
}

/// %XX escapes decoded, as tinygltf does for external URIs.
std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

/// The media types of the data: URIs tinygltf decodes for a buffer.
constexpr std::array<std::string_view, 7> kDataUriTypes = {"application/octet-stream",
                                                           "application/gltf-buffer",
                                                           "image/jpeg",
                                                           "image/png",
                                                           "image/bmp",
                                                           "image/gif",
                                                           "text/plain"};

/// Buffer `index` with a data: URI: base64 of one of tinygltf's media types, decoding to
/// exactly its byteLength.
void check_data_uri(const std::string& uri, std::uint64_t byte_length, const std::string& what,
                    const std::string& name) {
  const std::size_t marker = uri.find(";base64,");
  if (marker == std::string::npos) {
    fail(name, what + ": a data: URI without ';base64,' (only base64 data is read)");
  }
  const std::string_view type = std::string_view(uri).substr(5, marker - 5);
  if (std::find(kDataUriTypes.begin(), kDataUriTypes.end(), type) == kDataUriTypes.end()) {
    fail(name, what + ": data: URI of media type '" + printable(std::string(type)) +
                   "' (expected application/octet-stream or application/gltf-buffer)");
  }
  const std::uint64_t decoded = base64_decoded_bytes(std::string_view(uri).substr(marker + 8));
  if (decoded != byte_length) {
    fail(name, what + ": its data: URI decodes to " + std::to_string(decoded) +
                   " bytes, its byteLength says " + std::to_string(byte_length));
  }
}

/// Buffer with an external URI: a regular file of exactly byteLength bytes (tinygltf's rule).
void check_buffer_file(const std::string& uri, std::uint64_t byte_length, const std::string& what,
                       const std::string& name, const std::filesystem::path& base_dir) {
  // Appended piecewise: "'" + std::string trips a g++ 12 -Wrestrict false positive.
  std::string shown_uri = "'";
  shown_uri += printable(uri.substr(0, 80));
  shown_uri += "'";
  const std::string decoded = percent_decoded(uri);
  if (decoded.find('\0') != std::string::npos) {
    fail(name, what + ": " + shown_uri + ": the path contains a NUL byte");
  }
  std::error_code ec;
  const std::filesystem::path path = base_dir / decoded;
  const auto status = std::filesystem::status(path, ec);
  if (ec) fail(name, what + ": cannot open " + shown_uri + ": " + ec.message());
  if (const std::string kind = unreadable_kind(status); !kind.empty()) {
    fail(name, what + ": cannot open " + shown_uri + ": " + kind);
  }
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(name, what + ": cannot open " + shown_uri + ": " + ec.message());
  if (size > kMaxInputFileBytes) {
    fail(name, what + ": " + shown_uri + " is larger than the " + size_text(kMaxInputFileBytes) +
                   " limit");
  }
  if (size != byte_length) {
    fail(name, what + ": " + shown_uri + " holds " + std::to_string(size) +
                   " bytes, its byteLength says " + std::to_string(byte_length));
  }
}

void check_buffers(const json& root, const std::string& name,
                   const std::filesystem::path& base_dir) {
  const auto buffers = root.find("buffers");
  if (buffers == root.end()) return;
  for (std::size_t i = 0; i < buffers->size(); ++i) {
    const json& buffer = (*buffers)[i];
    const std::string what = "buffers[" + std::to_string(i) + "]";
    const auto uri = buffer.find("uri");
    if (uri == buffer.end()) continue;  // the GLB's BIN chunk; tinygltf checks it
    const auto length = buffer.find("byteLength");
    if (length == buffer.end()) fail(name, what + ": byteLength missing");
    const auto byte_length = length->get<std::uint64_t>();
    const std::string text = uri->get<std::string>();
    if (text.rfind("data:", 0) == 0) {
      check_data_uri(text, byte_length, what, name);
    } else {
      check_buffer_file(text, byte_length, what, name, base_dir);
    }
  }
}

std::uint32_t load_u32(const char* bytes) {
  std::uint32_t value;
  std::memcpy(&value, bytes, 4);
  return value;
}

/// The JSON text of the file: all of it, or a GLB's JSON chunk after its header is checked
/// (glTF 2.0, 4.4: magic, version 2, total length, then the JSON chunk first), where tinygltf
/// would say "Invalid glTF binary" or read a version 1 file as version 2.
std::string_view json_text(std::string_view bytes, const std::string& name) {
  if (!is_glb(bytes)) return bytes;
  constexpr std::size_t kChunkData = 20;  // header 12, chunk length 4, chunk type 4
  if (bytes.size() < kChunkData) {
    fail(name, "binary glTF of " + std::to_string(bytes.size()) +
                   " bytes: too short for its header and JSON chunk");
  }
  if (const std::uint32_t version = load_u32(bytes.data() + 4); version != 2) {
    fail(name, "binary glTF version " + std::to_string(version) + " (covrast reads version 2)");
  }
  if (const std::uint32_t total = load_u32(bytes.data() + 8); total != bytes.size()) {
    fail(name, "binary glTF header says " + std::to_string(total) + " bytes, the file has " +
                   std::to_string(bytes.size()) + " (truncated or padded)");
  }
  if (load_u32(bytes.data() + 16) != 0x4E4F534Au) {
    fail(name, "binary glTF whose first chunk is not JSON");
  }
  const std::uint32_t length = load_u32(bytes.data() + 12);
  if (length > bytes.size() - kChunkData) {
    fail(name, "binary glTF JSON chunk of " + std::to_string(length) +
                   " bytes runs past the end of the file");
  }
  // The BIN chunk, when present, must lie inside the file too: tinygltf trusts its length
  // and would read past the end of the bytes.
  const std::size_t rest = bytes.size() - kChunkData - length;
  if (rest > 0) {
    if (rest < 8) fail(name, "binary glTF with a broken chunk header after the JSON chunk");
    const std::uint32_t bin_length = load_u32(bytes.data() + kChunkData + length);
    if (bin_length > rest - 8) {
      fail(name, "binary glTF BIN chunk of " + std::to_string(bin_length) +
                     " bytes runs past the end of the file");
    }
  }
  return bytes.substr(kChunkData, length);
}

/// KHR_lights_punctual: a light's range, when given, is > 0 (the extension's schema). tinygltf
/// reads an absent range as 0, which covrast takes for "infinite", so a range of 0 would pass
/// unseen; it is checked here, in the JSON (issue 28).
void check_light_ranges(const json& root, const std::string& name, std::string& warn) {
  const auto extensions = root.find("extensions");
  if (extensions == root.end() || !extensions->is_object()) return;
  const auto lights_extension = extensions->find("KHR_lights_punctual");
  if (lights_extension == extensions->end() || !lights_extension->is_object()) return;
  const auto lights = lights_extension->find("lights");
  if (lights == lights_extension->end() || !lights->is_array()) return;
  for (std::size_t i = 0; i < lights->size(); ++i) {
    const json& light = (*lights)[i];
    if (!light.is_object()) continue;
    const auto range = light.find("range");
    if (range == light.end() || (range->is_number() && range->get<double>() > 0.0)) continue;
    const std::string message = "KHR_lights_punctual lights[" + std::to_string(i) +
                                "].range: expected a number > 0, got " + shown(*range);
    const auto type = light.find("type");
    if (type != light.end() && *type == "directional") {
      warn += message + " (ignored: a directional light has no range)\n";
    } else {
      fail(name, message);
    }
  }
}

}  // namespace

void check_gltf_input(std::string_view bytes, const std::string& name,
                      const std::filesystem::path& base_dir, std::string& warn) {
  if (!is_glb(bytes)) {
    std::string_view text = bytes;
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos || text[first] != '{') {
      fail(name, "not a glTF file: neither a JSON object (.gltf) nor binary glTF (.glb)");
    }
  }
  const std::string_view text = json_text(bytes, name);
  if (std::size_t offset = 0; !json_depth_within(text, kMaxJsonDepth, offset)) {
    fail(name, "arrays and objects nested deeper than " + std::to_string(kMaxJsonDepth) +
                   " levels (at byte " + std::to_string(offset) + " of the JSON)");
  }
  json root;
  try {
    root = json::parse(text);
  } catch (const json::out_of_range&) {
    fail(name, "a number beyond the range of a double");
  } catch (const json::exception&) {
    return;  // a syntax error: tinygltf reports it with its line and column
  }
  const SchemaFindings found = check_schema(root);
  if (!found.errors.empty()) fail(name, found.errors.front());
  for (const std::string& warning : found.warnings) warn += warning + " (ignored)\n";
  check_buffers(root, name, base_dir);
  check_light_ranges(root, name, warn);
}

std::vector<std::string> gltf_schema_findings(std::string_view bytes, const std::string& name,
                                              std::vector<std::string>& warnings) {
  if (!is_glb(bytes) && bytes.find('{') == std::string_view::npos) return {};
  json root;
  try {
    const std::string_view text = json_text(bytes, name);
    std::size_t offset = 0;
    if (!json_depth_within(text, kMaxJsonDepth, offset)) return {};
    root = json::parse(text);
  } catch (const std::exception&) {
    return {};  // not glTF JSON: the load reports it
  }
  SchemaFindings found = check_schema(root);
  for (std::string& warning : found.warnings)
    warnings.push_back(name + ": " + warning + " (ignored)");
  for (std::string& error : found.errors) error = name + ": " + error;
  return found.errors;
}

tinygltf::FsCallbacks gltf_fs_callbacks() {
  tinygltf::FsCallbacks callbacks{};
  callbacks.FileExists = [](const std::string& path, void*) {
    std::error_code ec;
    return path.find('\0') == std::string::npos && std::filesystem::exists(path, ec);
  };
  callbacks.ExpandFilePath = [](const std::string& path, void*) { return path; };
  callbacks.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err,
                               const std::string& path, void*) {
    // Read straight into tinygltf's vector, its size checked before (fstat): no second copy.
    std::string error;
    if (!read_whole_file(path, *out, error)) {
      if (err != nullptr) *err += error;
      return false;
    }
    return true;
  };
  callbacks.WriteWholeFile = [](std::string* err, const std::string&,
                                const std::vector<unsigned char>&, void*) {
    if (err != nullptr) *err += "covrast does not write glTF files";
    return false;
  };
  callbacks.user_data = nullptr;
  return callbacks;
}

void add_loader_warnings(const std::string& warn, const std::string& name,
                         std::vector<std::string>& out) {
  std::size_t begin = 0;
  while (begin < warn.size()) {
    std::size_t end = warn.find('\n', begin);
    if (end == std::string::npos) end = warn.size();
    std::string line = warn.substr(begin, end - begin);
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (!line.empty()) out.push_back(name + ": " + printable(line));
    begin = end + 1;
  }
}

}  // namespace covrast::detail
