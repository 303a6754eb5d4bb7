// glTF textures for the glTF loader (mesh_gltf.cpp): images decoded by covrast's own decoder
// (image_io.cpp: libspng, libturbojpeg), never by tinygltf's stb_image, samplers, and the
// material slots with texCoord and KHR_texture_transform (docs/textures.md).
#pragma once

#include "scene/gltf_accessors.hpp"

#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include <tiny_gltf.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>

namespace covrast::detail {

/// tinygltf's image callback (TinyGLTF::SetImageLoader): keeps the raw bytes of an image from
/// a file or a data: URI in Image::image (as_is) without decoding them; images in a buffer
/// view are read later, bounds-checked, from the view.
bool keep_image_bytes(tinygltf::Image* image, const int image_index, std::string* error,
                      std::string* warning, int, int, const unsigned char* bytes, int size, void*);

/// The textures of one glTF file: each image decoded and mipmapped at most once per colour
/// space, shared by every material slot that uses it.
class GltfTextures {
 public:
  /// `warnings` receives a line for each image file that does not exist.
  GltfTextures(const tinygltf::Model& model, const GltfReader& reader,
               std::filesystem::path base_dir, std::vector<std::string>& warnings)
      : model_(model), reader_(reader), base_dir_(std::move(base_dir)), warnings_(warnings) {}

  /// Fills the texture slots of `material` from `source`. An image file that does not exist
  /// leaves its slots empty with a warning (docs/limits.md, "Missing files"); one that cannot
  /// be read or decoded is an InputError naming the file and the image.
  void apply(const tinygltf::Material& source, int material_index, Material& material);
  /// The slot of a textureInfo (or normalTextureInfo: its "scale" too) given as JSON inside an
  /// extension, at JSON path `path`; every field checked (index, texCoord, scale, extensions).
  TextureSlot info_slot(const tinygltf::Value& info, bool srgb, const std::string& path);
  const std::string& file_name() const { return reader_.name; }

 private:
  TextureSlot slot(int texture_index, int texcoord, const tinygltf::ExtensionMap& extensions,
                   bool srgb, const std::string& what);
  /// The image a texture draws: EXT_texture_webp's source when it has one, else its core one.
  int image_source(const tinygltf::Texture& texture, const std::string& what) const;
  std::shared_ptr<const Texture> image_texture(int image_index, bool srgb, const std::string& what);
  RgbaImage decode(const tinygltf::Image& image, const std::string& image_name) const;
  /// What identifies an image's bytes: its buffer view, its file, or else the entry itself.
  std::string source_key(int image_index, const tinygltf::Image& image) const;

  const tinygltf::Model& model_;
  const GltfReader& reader_;
  std::filesystem::path base_dir_;
  std::vector<std::string>& warnings_;
  std::map<std::pair<int, bool>, std::shared_ptr<const Texture>> textures_;
  std::map<std::pair<std::string, bool>, std::shared_ptr<const Texture>> by_source_;
  std::uint64_t texels_ = 0;  ///< level-0 texels of the textures decoded so far
};

}  // namespace covrast::detail
