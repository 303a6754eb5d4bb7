// glTF textures (see gltf_textures.hpp; formulas and conventions in docs/textures.md).
#include "scene/gltf_textures.hpp"
#include "scene/scene_internal.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

namespace covrast::detail {

bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  if (image->bufferView >= 0) return true;  // read from the view, bounds-checked (decode())
  // An image file (tinygltf keeps its uri, not a data: URI's): read again by decode() when a
  // material uses it, once per distinct file, rather than a copy kept per image entry (eight
  // entries naming one file were eight copies, issue 28).
  if (!image->uri.empty()) return true;
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

namespace {

/// A URI's %XX escapes decoded (RFC 3986, 2.1), as tinygltf decodes it before opening.
std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    const auto hex = [](char c) {
      return c >= '0' && c <= '9'   ? c - '0'
             : c >= 'a' && c <= 'f' ? c - 'a' + 10
             : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                    : -1;
    };
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

/// glTF 2.0, 5.26 (sampler): wrap codes 33071, 33648, 10497; filters 9728 NEAREST, 9729
/// LINEAR, 9984..9987 the mipmapped minifications. Undefined filters keep the defaults.
TextureWrap wrap_mode(int code) {
  if (code == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return TextureWrap::ClampToEdge;
  if (code == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return TextureWrap::MirroredRepeat;
  return TextureWrap::Repeat;
}

/// glTF 2.0, 5.26: the sampler's enums are these codes (or absent: -1 for the filters). A
/// sampler a material uses with any other code is an error (issue 28: they were taken for
/// the defaults without a word).
void check_sampler(const tinygltf::Sampler& s, const std::string& name, const std::string& what) {
  const auto wrap = [](int code) {
    return code == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE ||
           code == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT || code == TINYGLTF_TEXTURE_WRAP_REPEAT;
  };
  if (s.magFilter != -1 && s.magFilter != TINYGLTF_TEXTURE_FILTER_NEAREST &&
      s.magFilter != TINYGLTF_TEXTURE_FILTER_LINEAR) {
    fail(name, what + ": magFilter " + std::to_string(s.magFilter) +
                   " is not 9728 (NEAREST) or 9729 (LINEAR)");
  }
  if (s.minFilter != -1 && s.minFilter != TINYGLTF_TEXTURE_FILTER_NEAREST &&
      s.minFilter != TINYGLTF_TEXTURE_FILTER_LINEAR &&
      !(s.minFilter >= TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST &&
        s.minFilter <= TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR)) {
    fail(name,
         what + ": minFilter " + std::to_string(s.minFilter) + " is not 9728, 9729 or 9984..9987");
  }
  if (!wrap(s.wrapS) || !wrap(s.wrapT)) {
    fail(name, what + ": " +
                   (wrap(s.wrapS) ? "wrapT " + std::to_string(s.wrapT)
                                  : "wrapS " + std::to_string(s.wrapS)) +
                   " is not 33071, 33648 or 10497");
  }
}

TextureSampler sampler_of(const tinygltf::Sampler& s) {
  TextureSampler out;
  out.wrap_s = wrap_mode(s.wrapS);
  out.wrap_t = wrap_mode(s.wrapT);
  if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) out.mag = TextureFilter::Nearest;
  switch (s.minFilter) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
      out.min = TextureFilter::Nearest;
      out.mip = MipFilter::None;
      break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR:
      out.mip = MipFilter::None;
      break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
      out.min = TextureFilter::Nearest;
      out.mip = MipFilter::Nearest;
      break;
    case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
      out.mip = MipFilter::Nearest;
      break;
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
      out.min = TextureFilter::Nearest;
      break;
    default:  // LINEAR_MIPMAP_LINEAR, or none given
      break;
  }
  return out;
}

/// KHR_texture_transform's number `key` of `object`, `fallback` when absent; any other type
/// is an error (the schema says number: tinygltf would hand over anything).
double number_or(const tinygltf::Value& object, const char* key, double fallback,
                 const std::string& name, const std::string& where) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble())) {
    fail(name, where + "." + key + ": expected a number");
  }
  return v.GetNumberAsDouble();
}

/// KHR_texture_transform's pair `key` (offset, scale): an array of two numbers, or absent.
glm::dvec2 pair_or(const tinygltf::Value& object, const char* key, glm::dvec2 fallback,
                   const std::string& name, const std::string& where) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& a = object.Get(key);
  if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber() ||
      !std::isfinite(a.Get(0).GetNumberAsDouble()) ||
      !std::isfinite(a.Get(1).GetNumberAsDouble())) {
    fail(name, where + "." + key + ": expected an array of 2 numbers");
  }
  return {a.Get(0).GetNumberAsDouble(), a.Get(1).GetNumberAsDouble()};
}

/// The media types of a glTF image's data: URI that covrast reads.
constexpr std::string_view kImageDataUriTypes =
    "expected image/png, image/jpeg or application/octet-stream";

}  // namespace

void count_texture_texels(int width, int height, const std::string& name,
                          std::uint64_t& texels_used) {
  const std::uint64_t texels = std::uint64_t(width) * std::uint64_t(height);
  if (texels > kMaxTextureTexels - texels_used) {
    throw InputError(name + ": its " + std::to_string(width) + "x" + std::to_string(height) +
                     " texels take the file's decoded images past " +
                     std::to_string(kMaxTextureTexels) + " texels (docs/limits.md)");
  }
  texels_used += texels;
}

std::shared_ptr<const Texture> load_texture_file(const std::filesystem::path& path,
                                                 const std::string& name, bool srgb,
                                                 std::uint64_t& texels_used) {
  RgbaImage image = read_image(path, name);
  count_texture_texels(image.width, image.height, name, texels_used);
  return make_texture(name, image.width, image.height, std::move(image.rgba), srgb);
}

RgbaImage GltfTextures::decode(const tinygltf::Image& image, const std::string& image_name) const {
  if (image.bufferView >= 0) {
    const unsigned char* bytes = reader_.view_bytes(image_name, image.bufferView);
    const std::size_t size = model_.bufferViews[std::size_t(image.bufferView)].byteLength;
    return decode_image(bytes, size, image_name);
  }
  if (!image.image.empty()) {
    // A data: URI tinygltf decoded; it names the media types it knows in mimeType (none for
    // application/octet-stream). Only PNG and JPEG are read, by their content.
    if (!image.mimeType.empty() && image.mimeType != "image/png" &&
        image.mimeType != "image/jpeg") {
      throw InputError(image_name + ": data: URI of media type '" + printable(image.mimeType) +
                       "' (" + std::string(kImageDataUriTypes) + ")");
    }
    return decode_image(image.image.data(), image.image.size(), image_name);
  }
  if (image.uri.empty()) throw InputError(image_name + ": no image data");
  // A data: URI of a media type tinygltf does not decode, which it takes for a file name.
  if (image.uri.rfind("data:", 0) == 0) {
    const std::size_t end = image.uri.find_first_of(";,", 5);
    throw InputError(image_name + ": data: URI of media type '" +
                     printable(image.uri.substr(5, std::min<std::size_t>(end, 60) - 5)) + "' (" +
                     std::string(kImageDataUriTypes) + ")");
  }
  // An image file: read here (tinygltf's copy is not kept, keep_image_bytes), its size checked
  // before it is read. A %00 escape would otherwise open the path before the NUL.
  const std::string path = percent_decoded(image.uri);
  if (path.find('\0') != std::string::npos) {
    throw InputError(image_name + ": the path contains a NUL byte");
  }
  return read_image(base_dir_ / path, image_name);
}

std::string GltfTextures::source_key(int image_index, const tinygltf::Image& image) const {
  if (image.bufferView >= 0) return "view " + std::to_string(image.bufferView);
  if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0) {
    return "file " + (base_dir_ / percent_decoded(image.uri)).lexically_normal().string();
  }
  return "image " + std::to_string(image_index);
}

std::shared_ptr<const Texture> GltfTextures::image_texture(int image_index, bool srgb,
                                                           const std::string& what) {
  if (image_index < 0 || std::size_t(image_index) >= model_.images.size()) {
    fail(reader_.name, what + ": image " + std::to_string(image_index) + " does not exist");
  }
  const auto key = std::make_pair(image_index, srgb);
  if (const auto it = textures_.find(key); it != textures_.end()) return it->second;
  const tinygltf::Image& image = model_.images[std::size_t(image_index)];
  std::string image_name = reader_.name + ": image " + std::to_string(image_index);
  if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0) {
    image_name += " (" + printable(image.uri) + ")";
  } else if (!image.name.empty()) {
    image_name += " (" + printable(image.name) + ")";
  }
  // Image entries that name the same file or buffer view share one decoded texture.
  const auto source = std::make_pair(source_key(image_index, image), srgb);
  if (const auto it = by_source_.find(source); it != by_source_.end()) {
    textures_.emplace(key, it->second);
    return it->second;
  }
  // A missing image file changes how the model looks, not what it is: drawn without it, with
  // a warning (--strict: an error), as a missing OBJ material library or map_Kd.
  if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0 && image.bufferView < 0) {
    std::error_code ec;
    const std::filesystem::path file = base_dir_ / percent_decoded(image.uri);
    if (!std::filesystem::exists(file, ec) && !ec) {
      warnings_.push_back(image_name + ": no such file: its texture slots are drawn without it");
      textures_.emplace(key, nullptr);
      by_source_.emplace(source, nullptr);
      return nullptr;
    }
  }
  // The decoded bytes become level 0 (moved, not copied): nothing else keeps them.
  RgbaImage rgba = decode(image, image_name);
  // The file's decoded images together stay within kMaxTextureTexels, checked before this
  // one's mipmaps are built (docs/limits.md).
  count_texture_texels(rgba.width, rgba.height, image_name, texels_);
  auto texture = make_texture(image_name, rgba.width, rgba.height, std::move(rgba.rgba), srgb);
  textures_.emplace(key, texture);
  by_source_.emplace(source, texture);
  return texture;
}

int GltfTextures::image_source(const tinygltf::Texture& texture, const std::string& what) const {
  // EXT_texture_webp: {"source": image index} takes the place of the core source, which is
  // then the fallback for viewers without WebP (and may be absent when the file requires it).
  const auto it = texture.extensions.find("EXT_texture_webp");
  if (it == texture.extensions.end()) {
    if (texture.source < 0) {
      // Only an image format covrast cannot read (KHR_texture_basisu, EXT_texture_avif), and
      // no core image, which such a file must give unless it requires the extension.
      std::string formats;
      for (const auto& [extension, value] : texture.extensions) {
        formats += (formats.empty() ? "" : ", ") + printable(extension);
      }
      fail(reader_.name,
           what + ": the texture has no image covrast can read (no \"source\"" +
               (formats.empty() ? std::string()
                                : "; only " + formats + ", which covrast cannot read") +
               ")");
    }
    return texture.source;
  }
  const std::string where = what + ": EXT_texture_webp";
  const tinygltf::Value& webp = it->second;
  if (!webp.IsObject() || !webp.Has("source")) {
    fail(reader_.name, where + ": expected an object with \"source\"");
  }
  const tinygltf::Value& source = webp.Get("source");
  const std::optional<int> index =
      source.IsNumber() ? whole_number(source, 0, int(model_.images.size()) - 1) : std::nullopt;
  if (!index) {
    fail(reader_.name, where + ".source: expected the index of one of the file's " +
                           std::to_string(model_.images.size()) + " images");
  }
  return *index;
}

TextureSlot GltfTextures::slot(int texture_index, int texcoord,
                               const tinygltf::ExtensionMap& extensions, bool srgb,
                               const std::string& what) {
  TextureSlot out;
  if (texture_index < 0) return out;
  if (std::size_t(texture_index) >= model_.textures.size()) {
    fail(reader_.name, what + ": texture " + std::to_string(texture_index) + " does not exist");
  }
  const tinygltf::Texture& texture = model_.textures[std::size_t(texture_index)];
  if (texture.sampler >= 0) {
    if (std::size_t(texture.sampler) >= model_.samplers.size()) {
      fail(reader_.name, what + ": sampler " + std::to_string(texture.sampler) + " does not exist");
    }
    const tinygltf::Sampler& sampler = model_.samplers[std::size_t(texture.sampler)];
    check_sampler(sampler, reader_.name, what + ": sampler " + std::to_string(texture.sampler));
    out.sampler = sampler_of(sampler);
  }
  out.texcoord = texcoord;
  // KHR_texture_transform on the textureInfo: offset, rotation, scale, texCoord override.
  // Each field of a wrong type is an error: the transform is used (issue 28).
  const std::string texcoord_range = " (covrast reads TEXCOORD_0 and TEXCOORD_1)";
  if (const auto it = extensions.find("KHR_texture_transform"); it != extensions.end()) {
    const tinygltf::Value& t = it->second;
    const std::string where = what + ": KHR_texture_transform";
    if (!t.IsObject()) fail(reader_.name, where + ": expected an object");
    out.transform.offset = pair_or(t, "offset", glm::dvec2(0.0), reader_.name, where);
    out.transform.rotation = number_or(t, "rotation", 0.0, reader_.name, where);
    out.transform.scale = pair_or(t, "scale", glm::dvec2(1.0), reader_.name, where);
    if (t.Has("texCoord")) {
      // Range-checked as a double before it becomes an int (1e30 was undefined behaviour).
      const tinygltf::Value& set = t.Get("texCoord");
      if (!set.IsNumber()) fail(reader_.name, where + ".texCoord: expected an integer >= 0");
      const std::optional<int> index = whole_number(set, 0, kMaxTexcoordSets - 1);
      if (!index) {
        fail(reader_.name,
             what + ": texCoord " + number_text(set.GetNumberAsDouble()) + texcoord_range);
      }
      out.texcoord = *index;
    }
  }
  if (out.texcoord < 0 || out.texcoord >= kMaxTexcoordSets) {
    fail(reader_.name, what + ": texCoord " + std::to_string(out.texcoord) + texcoord_range);
  }
  out.texture = image_texture(image_source(texture, what), srgb, what);
  return out;
}

TextureSlot GltfTextures::info_slot(const tinygltf::Value& info, bool srgb,
                                    const std::string& path) {
  if (!info.IsObject() || !info.Has("index")) {
    fail(reader_.name, path + ": expected a textureInfo object with \"index\"");
  }
  const tinygltf::Value& index = info.Get("index");
  const std::optional<int> texture =
      index.IsNumber() ? whole_number(index, 0, int(model_.textures.size()) - 1) : std::nullopt;
  if (!texture) {
    fail(reader_.name, path + ".index: expected the index of one of the file's " +
                           std::to_string(model_.textures.size()) + " textures");
  }
  int texcoord = 0;
  if (info.Has("texCoord")) {
    const tinygltf::Value& set = info.Get("texCoord");
    const std::optional<int> value =
        set.IsNumber() ? whole_number(set, 0, kMaxTexcoordSets - 1) : std::nullopt;
    if (!value) {
      fail(reader_.name, path + ".texCoord: expected 0 or 1 (covrast reads TEXCOORD_0 and _1)");
    }
    texcoord = *value;
  }
  tinygltf::ExtensionMap extensions;
  if (info.Has("extensions")) {
    const tinygltf::Value& object = info.Get("extensions");
    if (!object.IsObject()) fail(reader_.name, path + ".extensions: expected an object");
    for (const std::string& key : object.Keys()) extensions.emplace(key, object.Get(key));
  }
  TextureSlot out = slot(*texture, texcoord, extensions, srgb, path);
  out.scale = float(number_or(info, "scale", 1.0, reader_.name, path));
  return out;
}

void GltfTextures::apply(const tinygltf::Material& source, int material_index, Material& m) {
  const std::string what = "material " + std::to_string(material_index);
  const tinygltf::PbrMetallicRoughness& pbr = source.pbrMetallicRoughness;
  m.base_color_texture = slot(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                              pbr.baseColorTexture.extensions, true, what + " baseColorTexture");
  m.metallic_roughness_texture =
      slot(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
           pbr.metallicRoughnessTexture.extensions, false, what + " metallicRoughnessTexture");
  m.normal_texture = slot(source.normalTexture.index, source.normalTexture.texCoord,
                          source.normalTexture.extensions, false, what + " normalTexture");
  m.normal_texture.scale =
      float(std::isfinite(source.normalTexture.scale) ? source.normalTexture.scale : 1.0);
  m.occlusion_texture = slot(source.occlusionTexture.index, source.occlusionTexture.texCoord,
                             source.occlusionTexture.extensions, false, what + " occlusionTexture");
  const double strength = source.occlusionTexture.strength;
  m.occlusion_texture.scale = float(std::isfinite(strength) ? std::clamp(strength, 0.0, 1.0) : 1.0);
  m.emissive_texture = slot(source.emissiveTexture.index, source.emissiveTexture.texCoord,
                            source.emissiveTexture.extensions, true, what + " emissiveTexture");
}

}  // namespace covrast::detail
