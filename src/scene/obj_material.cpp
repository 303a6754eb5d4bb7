// .mtl reader. Mapping (docs/scene-format.md, "OBJ materials"): Kd -> base colour (linear,
// like glTF's baseColorFactor); Ks, Ns -> blinn-phong specular colour and exponent; Ke ->
// emission; d (or 1 - Tr) -> Material::base_alpha; map_Kd -> Material::base_color_texture_path;
// illum 0 -> unlit, illum 1 -> lambert, otherwise blinn-phong when Ks is non-zero, else lambert.
#include "scene/obj_material.hpp"

#include "scene/obj_text.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <optional>

namespace covrast::detail {
namespace {

/// Statements that carry nothing covrast's models could use (ambient colour: the ambient term
/// uses the base colour; refraction index, transmission filter, reflection sharpness): read
/// without a warning.
constexpr std::string_view kIgnored[] = {"Ka", "Ni", "Tf", "sharpness"};

/// One .mtl file's statements, read line by line.
class MtlParser {
 public:
  MtlParser(const std::string& name, const std::filesystem::path& directory, MtlLibrary& library)
      : name_(name), directory_(directory), library_(library) {}

  void read_line(std::string_view line, std::size_t line_no) {
    Tokens tokens(without_comment(line));
    std::string_view keyword;
    if (!tokens.next(keyword)) return;
    line_no_ = line_no;
    if (keyword == "newmtl") {
      finish_material();
      current_ = ObjMaterial{};
      current_->name = std::string(tokens.rest());
      return;
    }
    if (std::find(std::begin(kIgnored), std::end(kIgnored), keyword) != std::end(kIgnored)) return;
    if (!current_ && is_used(keyword)) {
      fail_at(name_, line_no, std::string(keyword) + " before the first newmtl");
    }
    if (keyword == "Kd") {
      current_->diffuse_linear = color(tokens, keyword, 1.0);
    } else if (keyword == "Ks") {
      current_->material.specular_linear = color(tokens, keyword, 1.0);
      has_ks_ = true;
    } else if (keyword == "Ke") {
      current_->material.emissive_linear = color(tokens, keyword, 1e30);
    } else if (keyword == "Ns") {
      // MTL's exponent runs 0..1000; covrast's blinn-phong takes 0.001..10000.
      const double ns = number(tokens, keyword, 0.0, 1e30);
      current_->material.shininess = static_cast<float>(std::clamp(ns, 1e-3, 1e4));
    } else if (keyword == "d") {
      current_->material.base_alpha = number(tokens, keyword, 0.0, 1.0);
      has_d_ = true;
    } else if (keyword == "Tr") {
      const double tr = number(tokens, keyword, 0.0, 1.0);
      if (!has_d_) current_->material.base_alpha = 1.0 - tr;  // d wins where both are given
    } else if (keyword == "illum") {
      illum_ = static_cast<long long>(number(tokens, keyword, 0.0, 10.0));
    } else if (keyword == "map_Kd") {
      texture(tokens);
    } else {
      ++unused_[std::string(printable(keyword))];
    }
  }

  void finish() {
    finish_material();
    if (unused_.empty()) return;
    std::size_t total = 0;
    std::string list;
    for (const auto& [keyword, count] : unused_) {
      total += count;
      list += (list.empty() ? "" : ", ") + keyword + " " + std::to_string(count);
    }
    library_.warnings.push_back(name_ + ": " + std::to_string(total) + " statements not used (" +
                                list + "): covrast does not render them");
  }

 private:
  static bool is_used(std::string_view keyword) {
    return keyword == "Kd" || keyword == "Ks" || keyword == "Ke" || keyword == "Ns" ||
           keyword == "d" || keyword == "Tr" || keyword == "illum" || keyword == "map_Kd";
  }

  /// One number in [lo, hi].
  double number(Tokens& tokens, std::string_view keyword, double lo, double hi) const {
    std::string_view token;
    double value = 0.0;
    if (!tokens.next(token) || !parse_double(token, value)) {
      fail_at(name_, line_no_, std::string(keyword) + ": expected a number");
    }
    if (!(value >= lo && value <= hi)) {
      fail_at(name_, line_no_,
              std::string(keyword) + ": " + printable(token) + " out of range " +
                  (hi > 1e29 ? ">= " + std::to_string(int(lo)) : "0..1"));
    }
    return value;
  }

  /// "r [g b]" (one number stands for all three, as the MTL format allows), each in [0, hi].
  glm::vec3 color(Tokens& tokens, std::string_view keyword, double hi) const {
    glm::vec3 c(static_cast<float>(number(tokens, keyword, 0.0, hi)));
    std::string_view token;
    Tokens rest = tokens;
    if (rest.next(token)) {
      c.g = static_cast<float>(number(tokens, keyword, 0.0, hi));
      c.b = static_cast<float>(number(tokens, keyword, 0.0, hi));
    }
    return c;
  }

  /// "map_Kd [options] file": the options of the MTL format come first, each with its values
  /// (-o, -s and -t take one to three numbers, -mm two, the others one); the rest of the line
  /// is the file name, spaces included ("my tex.png", issue 28: the last token was taken),
  /// resolved against the .mtl file's directory.
  void texture(Tokens& tokens) {
    static constexpr std::array<std::pair<std::string_view, int>, 12> kOptions = {{
        {"-blendu", 1},
        {"-blendv", 1},
        {"-bm", 1},
        {"-boost", 1},
        {"-cc", 1},
        {"-clamp", 1},
        {"-imfchan", 1},
        {"-mm", 2},
        {"-o", 3},
        {"-s", 3},
        {"-t", 3},
        {"-texres", 1},
    }};
    for (;;) {
      Tokens ahead = tokens;
      std::string_view option;
      if (!ahead.next(option)) break;
      const auto known = std::find_if(kOptions.begin(), kOptions.end(),
                                      [&](const auto& o) { return o.first == option; });
      if (known == kOptions.end()) break;  // the file name (which may start with '-')
      tokens = ahead;
      const bool vector = known->second == 3;  // -o, -s, -t
      for (int k = 0; k < known->second; ++k) {
        Tokens value_ahead = tokens;
        std::string_view value;
        double number = 0.0;
        if (!value_ahead.next(value)) {
          fail_at(name_, line_no_,
                  "map_Kd: option " + std::string(known->first) + " needs a value");
        }
        // -o, -s and -t: u, then v and w when they are numbers.
        if (vector && k > 0 && !parse_double(value, number)) break;
        tokens = value_ahead;
      }
    }
    const std::string_view file = tokens.rest();
    if (file.empty()) fail_at(name_, line_no_, "map_Kd: expected a file name");
    current_->material.base_color_texture_path =
        (directory_ / std::filesystem::path(std::string(file))).lexically_normal().string();
  }

  /// The entry read so far: its shading model from illum and Ks, then into the library.
  void finish_material() {
    if (!current_) return;
    Material& m = current_->material;
    const glm::vec3& ks = m.specular_linear;
    const bool has_specular = has_ks_ && (ks.r > 0.0f || ks.g > 0.0f || ks.b > 0.0f);
    if (illum_ == 0) {
      m.model = ShadingModel::Unlit;
    } else if (illum_ == 1 || !has_specular) {
      m.model = ShadingModel::Lambert;
    } else {
      m.model = ShadingModel::BlinnPhong;
    }
    library_.add(std::move(*current_));
    current_.reset();
    has_d_ = false;
    has_ks_ = false;
    illum_ = -1;
  }

  const std::string& name_;
  const std::filesystem::path& directory_;
  MtlLibrary& library_;
  std::optional<ObjMaterial> current_;
  bool has_d_ = false;
  bool has_ks_ = false;
  long long illum_ = -1;  ///< -1: not given
  std::size_t line_no_ = 0;
  std::map<std::string, std::size_t> unused_;  ///< keyword -> count, sorted for the message
};

}  // namespace

long MtlLibrary::find(std::string_view name) const {
  const auto it = index_.find(std::string(name));
  return it == index_.end() ? -1 : static_cast<long>(it->second);
}

void MtlLibrary::add(ObjMaterial material) {
  const auto [it, added] = index_.try_emplace(material.name, materials.size());
  if (added) {
    materials.push_back(std::move(material));
  } else {
    materials[it->second] = std::move(material);
  }
}

void parse_mtl(std::string_view text, const std::string& display_name,
               const std::filesystem::path& directory, MtlLibrary& library) {
  MtlParser parser(display_name, directory, library);
  for_each_line(
      text, [&](std::string_view line, std::size_t line_no) { parser.read_line(line, line_no); });
  parser.finish();
}

}  // namespace covrast::detail

namespace covrast::detail {
namespace {

/// The base colour of each triangle's material as vertex colours: vertex colour (white where
/// the file has none) x Kd; a vertex used by triangles of two materials is copied for the
/// second (the copies have equal positions, so edges stay watertight and the topology
/// analysis welds them).
void diffuse_vertex_colors(const std::vector<glm::vec3>& kd, MeshData& mesh) {
  const std::size_t original = mesh.positions.size();
  std::vector<glm::vec3> base = mesh.colors_linear;
  if (base.empty()) base.assign(original, glm::vec3(1.0f));
  std::vector<glm::vec3> colors = base;
  std::vector<std::uint32_t> owner(original, kNoObjMaterial);  // whose Kd a vertex carries
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> copies;
  for (std::size_t corner = 0; corner < mesh.indices.size(); ++corner) {
    const std::uint32_t v = mesh.indices[corner];
    const std::uint32_t m = mesh.triangle_materials[corner / 3];
    if (owner[v] == kNoObjMaterial) {
      owner[v] = m;
      colors[v] = base[v] * kd[m];
    } else if (owner[v] != m) {
      auto [it, added] = copies.try_emplace({v, m}, std::uint32_t(mesh.positions.size()));
      if (added) {
        mesh.positions.push_back(mesh.positions[v]);
        colors.push_back(base[v] * kd[m]);
      }
      mesh.indices[corner] = it->second;
    }
  }
  mesh.colors_linear = std::move(colors);
}

std::string quoted_list(const std::vector<std::string>& names) {
  constexpr std::size_t kMaxListed = 3;
  std::string list;
  for (std::size_t i = 0; i < names.size() && i < kMaxListed; ++i) {
    list += (i > 0 ? ", '" : "'") + printable(names[i]) + "'";
  }
  if (names.size() > kMaxListed) list += ", ...";
  return list;
}

}  // namespace

void apply_obj_materials(const MtlLibrary& library, const std::vector<std::string>& names,
                         const std::vector<std::uint32_t>& triangle_names,
                         const std::string& obj_name, LoadedMesh& loaded) {
  MeshData& mesh = *loaded.data;
  std::vector<std::uint32_t> material_of_name(names.size(), kNoObjMaterial);
  std::vector<std::string> unknown;
  std::vector<glm::vec3> kd;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const long found = library.find(names[i]);
    if (found < 0) {
      unknown.push_back(names[i]);
      continue;
    }
    material_of_name[i] = static_cast<std::uint32_t>(mesh.materials.size());
    mesh.materials.push_back(library.materials[static_cast<std::size_t>(found)].material);
    kd.push_back(library.materials[static_cast<std::size_t>(found)].diffuse_linear);
  }
  if (!unknown.empty()) {
    loaded.warnings.push_back(obj_name + ": " + std::to_string(unknown.size()) +
                              " usemtl names not in its material libraries (" +
                              quoted_list(unknown) + "): the default material used");
  }
  if (mesh.materials.empty()) return;
  // The default material (lambert, white) for faces before any usemtl or with unknown names.
  const auto fallback = static_cast<std::uint32_t>(mesh.materials.size());
  Material lambert;
  lambert.model = ShadingModel::Lambert;
  mesh.materials.push_back(lambert);
  kd.emplace_back(1.0f);
  mesh.triangle_materials.resize(triangle_names.size());
  bool one_kd = true;
  for (std::size_t t = 0; t < triangle_names.size(); ++t) {
    const std::uint32_t name = triangle_names[t];
    const std::uint32_t m = name == kNoObjMaterial ? fallback : material_of_name[name];
    mesh.triangle_materials[t] = m == kNoObjMaterial ? fallback : m;
    one_kd = one_kd && kd[mesh.triangle_materials[t]] == kd[mesh.triangle_materials[0]];
  }
  if (mesh.triangle_materials.empty()) return;
  if (one_kd && mesh.colors_linear.empty()) {
    loaded.has_uniform_color = true;
    loaded.uniform_color_linear = kd[mesh.triangle_materials[0]];
  } else {
    diffuse_vertex_colors(kd, mesh);
  }
}

}  // namespace covrast::detail
