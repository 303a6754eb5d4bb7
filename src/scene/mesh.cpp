// Format-independent mesh loading: reading files, the NaN/Inf triangle filter shared by the
// OBJ and glTF parsers, and the public load_mesh entry point (format chosen by extension).
#include "scene/scene_internal.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <system_error>

namespace covrast {
namespace detail {

std::string size_text(std::uint64_t bytes) {
  if (bytes % (std::uint64_t(1) << 30) == 0) return std::to_string(bytes >> 30) + " GiB";
  if (bytes % (std::uint64_t(1) << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

namespace {

/// read_whole_file into a std::string or a byte vector.
template <class Buffer>
bool read_whole_file_into(const std::filesystem::path& path, Buffer& contents, std::string& error,
                          std::uint64_t max_bytes) {
  const auto system_error = [&](int code) {
    error = std::error_code(code, std::generic_category()).message();
    return false;
  };
  // A path string with an embedded NUL would quietly open its prefix.
  if (path.native().find('\0') != std::string::npos) {
    error = "the path contains a NUL byte";
    return false;
  }
  // O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses everything
  // that is not a regular file (FIFOs, devices such as /dev/zero, directories), checked on
  // the opened file itself so that nothing can swap it in between.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return system_error(errno);
  const std::unique_ptr<int, void (*)(int*)> closer(new int(fd), [](int* f) {
    ::close(*f);
    delete f;
  });
  struct stat info {};
  if (::fstat(fd, &info) != 0) return system_error(errno);
  if (S_ISDIR(info.st_mode)) return system_error(EISDIR);
  if (!S_ISREG(info.st_mode)) {
    error = "not a regular file";
    return false;
  }
  const auto size = static_cast<std::uint64_t>(info.st_size);
  if (size > max_bytes) {
    error = "file of " + std::to_string(size) + " bytes is larger than the " +
            size_text(max_bytes) + " limit";
    return false;
  }
  contents.assign(static_cast<std::size_t>(size), '\0');
  std::size_t done = 0;
  while (done < contents.size()) {
    const ssize_t got = ::read(fd, contents.data() + done, contents.size() - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return system_error(errno);
    if (got == 0) break;  // the file shrank meanwhile: keep what is there
    done += static_cast<std::size_t>(got);
  }
  contents.resize(done);
  return true;
}

}  // namespace

bool read_whole_file(const std::filesystem::path& path, std::string& contents, std::string& error,
                     std::uint64_t max_bytes) {
  return read_whole_file_into(path, contents, error, max_bytes);
}

bool read_whole_file(const std::filesystem::path& path, std::vector<unsigned char>& contents,
                     std::string& error, std::uint64_t max_bytes) {
  return read_whole_file_into(path, contents, error, max_bytes);
}

std::size_t drop_nonfinite_triangles(MeshData& mesh) {
  std::vector<bool> bad(mesh.positions.size(), false);
  bool any_bad = false;
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3& p = mesh.positions[i];
    if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
      bad[i] = true;
      any_bad = true;
    }
  }
  if (!any_bad) return 0;
  std::size_t kept = 0;
  std::size_t dropped = 0;
  const bool normals = !mesh.corner_normals.empty();
  const bool materials = !mesh.triangle_materials.empty();
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    if (bad[a] || bad[b] || bad[c]) {
      ++dropped;
      continue;
    }
    // The per-triangle arrays move with their triangle (kept is 3 x the triangles kept).
    if (normals)
      std::copy_n(mesh.corner_normals.begin() + std::ptrdiff_t(t), 3,
                  mesh.corner_normals.begin() + std::ptrdiff_t(kept));
    for (std::vector<glm::vec2>& uv : mesh.corner_texcoords) {
      if (!uv.empty())
        std::copy_n(uv.begin() + std::ptrdiff_t(t), 3, uv.begin() + std::ptrdiff_t(kept));
    }
    if (!mesh.corner_tangents.empty())
      std::copy_n(mesh.corner_tangents.begin() + std::ptrdiff_t(t), 3,
                  mesh.corner_tangents.begin() + std::ptrdiff_t(kept));
    if (materials) mesh.triangle_materials[kept / 3] = mesh.triangle_materials[t / 3];
    mesh.indices[kept++] = a;
    mesh.indices[kept++] = b;
    mesh.indices[kept++] = c;
  }
  mesh.indices.resize(kept);
  if (normals) mesh.corner_normals.resize(kept);
  for (std::vector<glm::vec2>& uv : mesh.corner_texcoords) {
    if (!uv.empty()) uv.resize(kept);
  }
  if (!mesh.corner_tangents.empty()) mesh.corner_tangents.resize(kept);
  if (materials) mesh.triangle_materials.resize(kept / 3);
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    if (bad[i]) mesh.positions[i] = glm::vec3(0.0f);
  }
  return dropped;
}

bool is_glb(std::string_view bytes) { return bytes.substr(0, 4) == "glTF"; }

void check_obj_text(std::string_view text, const std::string& name) {
  // OBJ is text: a NUL byte means binary data (a .glb, an image, a NUL-filled file), which
  // the line parser would skip line by line and load as nothing.
  if (is_glb(text))
    throw InputError(name + ": " +
                     "binary glTF (.glb), not an OBJ text file: name it with \"gltf\"");
  if (text.find('\0') != std::string_view::npos) {
    throw InputError(name + ": " + "binary data (a NUL byte at byte " +
                     std::to_string(text.find('\0')) + "), not an OBJ text file");
  }
  // JSON (a .gltf file, a scene) starts with an object or array; no OBJ statement does.
  std::string_view rest = text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
  const std::size_t first = rest.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && (rest[first] == '{' || rest[first] == '[')) {
    throw InputError(name + ": " + "JSON, not an OBJ file (a .gltf file belongs under \"gltf\")");
  }
}

}  // namespace detail

std::shared_ptr<MeshData> load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".obj" && ext != ".gltf" && ext != ".glb") {
    throw InputError(name + ": unknown mesh format (expected .obj, .gltf or .glb)");
  }
  std::string bytes;
  std::string error;
  if (!detail::read_whole_file(path, bytes, error)) {
    throw InputError(name + ": cannot open: " + error);
  }
  if (ext == ".obj") return detail::parse_obj(bytes, name, path.parent_path()).data;
  return detail::parse_gltf(bytes, name, path.parent_path()).data;
}

}  // namespace covrast
