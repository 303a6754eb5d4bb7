// Tests: the bad-input corpus (issue 15, item 7). Every case writes a few small malformed
// files into a fresh directory, runs the covrast executable on them there, and requires the
// exit code, one error line that starts with the expected text, and no file left behind that
// the case did not write (no partial output). The files are generated here, none committed.
#include <covrast/image.hpp>
#include <covrast/scene.hpp>

#include <sys/stat.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "test_cli_run.hpp"
#include "test_gltf_files.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using covrast::test::GltfBuilder;
using covrast::test::make_glb;
using covrast::test::put_u32;
using covrast::test::quoted;
using covrast::test::read_text;
using covrast::test::TempDir;
using covrast::test::write_text;
using nlohmann::json;

namespace {

/// One malformed input: the files it writes, the command line run in their directory, and
/// the exit code and start of the message ("covrast: error: " is prepended) it must give.
struct Case {
  Case(std::string name_, std::vector<std::pair<std::string, std::string>> files_,
       std::vector<std::string> args_, int exit_code_, std::string message_, std::string fifo_ = "")
      : name(std::move(name_)),
        files(std::move(files_)),
        args(std::move(args_)),
        exit_code(exit_code_),
        message(std::move(message_)),
        fifo(std::move(fifo_)) {}
  std::string name;
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<std::string> args;
  int exit_code = 2;
  std::string message;
  /// When not empty: a FIFO of this name is made in the directory (opening it to read
  /// would block until a writer comes).
  std::string fifo;
  /// With --strict: the start of the warning (after "warning: ") that must be printed
  /// after the error line.
  std::string warning;
};

/// A case run with --strict: `warning` must be printed and the run fails on it.
Case strict(Case c, std::string warning) {
  c.args.push_back("--strict");
  c.warning = std::move(warning);
  c.message = c.files.front().first + ": ";
  return c;
}

const std::string kCamera =
    R"("camera":{"eye":[0,0,3],"target":[0,0,0],"up":[0,1,0],"fovy_deg":45,"near":0.1,"far":100})";
const std::string kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

std::string scene_text(const std::string& meshes = R"([{"obj":"m.obj"}])",
                       const std::string& camera = kCamera, const std::string& extra = "") {
  return R"({"width":8,"height":8,)" + camera + R"(,"meshes":)" + meshes + extra + "}";
}

std::vector<std::string> render_args(std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"render", "s.json", "-o", "out.png"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

/// A scene file (and the good triangle OBJ it may name).
Case scene_case(std::string name, std::string scene, std::string message,
                std::vector<std::string> extra = {}) {
  return {std::move(name),
          {{"s.json", std::move(scene)}, {"m.obj", kTriangleObj}},
          render_args(std::move(extra)),
          2,
          std::move(message)};
}

/// An OBJ file named by a good scene.
Case obj_case(std::string name, std::string obj, std::string message, bool warns = false) {
  Case c{std::move(name),
         {{"s.json", scene_text()}, {"m.obj", std::move(obj)}},
         render_args(),
         2,
         std::move(message)};
  if (!warns) return c;
  std::string warning = c.message;
  return strict(std::move(c), std::move(warning));
}

/// A glTF file (`file` names it, .gltf or .glb) named by a good scene.
Case gltf_case(std::string name, std::string bytes, std::string message,
               const std::string& file = "m.gltf", bool warns = false) {
  Case c{std::move(name),
         {{"s.json", scene_text(R"([{"gltf":")" + file + R"("}])")}, {file, std::move(bytes)}},
         render_args(),
         2,
         std::move(message)};
  if (!warns) return c;
  std::string warning = c.message;
  return strict(std::move(c), std::move(warning));
}

/// A good one-triangle glTF document; `edit` changes it before it is written.
GltfBuilder triangle_gltf() {
  GltfBuilder builder;
  const int positions = builder.add_floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  builder.single_mesh({{{"attributes", {{"POSITION", positions}}}}});
  return builder;
}

std::string edited_gltf(const std::function<void(json&)>& edit) {
  json document = json::parse(triangle_gltf().gltf_text());
  edit(document);
  return document.dump();
}

std::string edited_glb(const std::function<void(json&)>& edit) {
  GltfBuilder builder = triangle_gltf();
  edit(builder.gltf);
  return builder.glb();
}

/// `depth` nested arrays around `inner`.
std::string nested(int depth, const std::string& inner = "1") {
  return std::string(std::size_t(depth), '[') + inner + std::string(std::size_t(depth), ']');
}

/// CRC-32 of PNG chunks (ISO 3309, the PNG specification's sample code).
std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const char c : bytes) {
    crc ^= static_cast<unsigned char>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xFFFFFFFFu;
}

void put_be32(std::string& out, std::uint32_t value) {
  for (int i = 3; i >= 0; --i) out += static_cast<char>((value >> (8 * i)) & 255u);
}

void put_chunk(std::string& out, const std::string& type, const std::string& data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  out += type + data;
  put_be32(out, crc32(type + data));
}

const std::string kPngSignature = "\x89PNG\r\n\x1a\n";

/// A PNG signature and IHDR of an 8-bit RGB image of `width` x `height` (no pixels yet).
std::string png_header(std::uint32_t width, std::uint32_t height) {
  std::string ihdr;
  put_be32(ihdr, width);
  put_be32(ihdr, height);
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);
  std::string out = kPngSignature;
  put_chunk(out, "IHDR", ihdr);
  return out;
}

/// A valid PNG of `width` x `height`, written by covrast's own encoder.
std::string good_png(int width, int height) {
  covrast::Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(std::size_t(width) * std::size_t(height) * 3, 100);
  const std::vector<std::uint8_t> bytes = covrast::encode_png(image);
  return std::string(bytes.begin(), bytes.end());
}

Case compare_case(std::string name, std::string a_bytes, std::string message) {
  return {std::move(name),
          {{"a.png", std::move(a_bytes)}, {"b.png", good_png(4, 4)}},
          {"compare", "a.png", "b.png"},
          2,
          std::move(message)};
}

/// A golden-test manifest (and a good scene and golden image it may name).
Case manifest_case(std::string name, std::string manifest, std::string message) {
  return {std::move(name),
          {{"t.json", std::move(manifest)},
           {"s.json", scene_text()},
           {"m.obj", kTriangleObj},
           {"g.png", good_png(8, 8)}},
          {"test", "t.json"},
          2,
          std::move(message)};
}

std::vector<Case> scene_cases();
std::vector<Case> obj_cases();
std::vector<Case> gltf_cases();
std::vector<Case> glb_cases();
std::vector<Case> png_cases();
std::vector<Case> manifest_cases();
std::vector<Case> output_cases();

std::vector<Case> all_cases() {
  std::vector<Case> cases;
  for (auto* group :
       {scene_cases, obj_cases, gltf_cases, glb_cases, png_cases, manifest_cases, output_cases}) {
    for (Case& c : group()) cases.push_back(std::move(c));
  }
  return cases;
}

/// Runs the CLI in `dir` under a time limit (a hang is a failure, exit 124), stdin empty.
covrast::test::RunResult run_in(const fs::path& dir, const std::vector<std::string>& args) {
  const fs::path out_file = dir.parent_path() / (dir.filename().string() + ".stdout");
  const fs::path err_file = dir.parent_path() / (dir.filename().string() + ".stderr");
  std::string command = "cd " + quoted(dir.string()) + " && timeout -k 5 60 ";
  command += quoted(COVRAST_CLI_PATH);
  for (const std::string& arg : args) {
    command += ' ';
    command += quoted(arg);
  }
  command += " >" + quoted(out_file.string()) + " 2>" + quoted(err_file.string()) + " </dev/null";
  const int status = std::system(command.c_str());
  covrast::test::RunResult result;
  REQUIRE(WIFEXITED(status));
  result.exit_code = WEXITSTATUS(status);
  result.out = read_text(out_file);
  result.err = read_text(err_file);
  fs::remove(out_file);
  fs::remove(err_file);
  return result;
}

std::set<std::string> directory_names(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.insert(entry.path().filename());
  return names;
}

}  // namespace

TEST_CASE("bad-input corpus: each malformed input gives its exit code and message",
          "[corpus][cli]") {
  const std::vector<Case> cases = all_cases();
  CHECK(cases.size() >= 100);
  std::set<std::string> names;
  TempDir root("covrast-corpus");
  for (const Case& c : cases) {
    INFO("case: " << c.name);
    CHECK(names.insert(c.name).second);  // names identify the cases
    const fs::path dir = root / std::to_string(names.size());
    fs::create_directories(dir);
    std::set<std::string> written;
    for (const auto& [file, bytes] : c.files) {
      write_text(dir / file, bytes);
      written.insert(file);
    }
    if (!c.fifo.empty()) {
      REQUIRE(::mkfifo((dir / c.fifo).c_str(), 0600) == 0);
      written.insert(c.fifo);
    }
    const covrast::test::RunResult r = run_in(dir, c.args);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == c.exit_code);
    // One error line, the first; after it only warnings (with --strict).
    std::vector<std::string> lines;
    std::istringstream stream(r.err);
    for (std::string line; std::getline(stream, line);) lines.push_back(line);
    REQUIRE(!lines.empty());
    const std::string expected = "covrast: error: " + c.message;
    CHECK(lines.front().compare(0, expected.size(), expected) == 0);
    bool warned = c.warning.empty();
    for (std::size_t i = 1; i < lines.size(); ++i) {
      CHECK(lines[i].rfind("warning: ", 0) == 0);
      warned = warned || lines[i].rfind("warning: " + c.warning, 0) == 0;
    }
    CHECK(warned);
    CHECK(directory_names(dir) == written);
  }
}

namespace {

std::vector<Case> scene_cases() {
  const std::string good = scene_text();
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
  };
  const std::string depth_limit = std::to_string(covrast::kMaxJsonDepth);
  std::vector<Case> cases = {
      scene_case("scene: empty file", "", "s.json:1:1: "),
      scene_case("scene: not JSON", "hello", "s.json:1:"),
      scene_case("scene: truncated", good.substr(0, good.size() / 2), "s.json:1:"),
      scene_case("scene: top level array", "[1,2]",
                 "s.json: expected a JSON object at the top level"),
      scene_case("scene: top level string", "\"x\"",
                 "s.json: expected a JSON object at the top level"),
      scene_case("scene: number overflow", with("\"width\":8", "\"width\":1e400"),
                 "s.json: number overflow"),
      scene_case("scene: negative number overflow", with("[0,0,3]", "[0,-1e3080,3]"),
                 "s.json: number overflow"),
      scene_case("scene: nested 80000 deep in eye", with("[0,0,3]", nested(80000)), "s.json:1:"),
      scene_case("scene: nested just past the limit",
                 with("[0,0,3]", nested(covrast::kMaxJsonDepth)), "s.json:1:"),
      scene_case("scene: objects nested deep",
                 with("\"meshes\":", "\"x\":" + std::string(50000, '{')), "s.json:1:"),
      scene_case("scene: width missing", with("\"width\":8,", ""), "s.json: width: missing"),
      scene_case("scene: width 0", with("\"width\":8", "\"width\":0"), "s.json: width: expected"),
      scene_case("scene: width huge", with("\"width\":8", "\"width\":1000000000"),
                 "s.json: width: expected"),
      scene_case("scene: width string", with("\"width\":8", "\"width\":\"8\""),
                 "s.json: width: expected"),
      scene_case("scene: width fraction", with("\"width\":8", "\"width\":8.5"),
                 "s.json: width: expected"),
      scene_case("scene: height negative", with("\"height\":8", "\"height\":-8"),
                 "s.json: height: expected"),
      scene_case("scene: camera missing", scene_text(R"([{"obj":"m.obj"}])", R"("x":1)"),
                 "s.json: camera: missing"),
      scene_case("scene: camera array", scene_text(R"([{"obj":"m.obj"}])", R"("camera":[1])"),
                 "s.json: camera: expected an object"),
      scene_case("scene: eye missing", with("\"eye\":[0,0,3],", ""), "s.json: camera.eye: missing"),
      scene_case("scene: eye two numbers", with("[0,0,3]", "[0,3]"),
                 "s.json: camera.eye: expected"),
      scene_case("scene: eye string element", with("[0,0,3]", "[0,\"0\",3]"),
                 "s.json: camera.eye[1]: expected a number"),
      scene_case("scene: eye at 1e308", with("[0,0,3]", "[1e308,1e308,1e308]"),
                 "s.json: camera.eye: too far"),
      scene_case("scene: up at 1e308", with("[0,1,0]", "[1e308,1e308,0]"),
                 "s.json: camera.up: too large"),
      scene_case("scene: up parallel", with("[0,1,0]", "[0,0,1]"), "s.json: camera.up: must not"),
      scene_case("scene: eye equals target", with("[0,0,3]", "[0,0,0]"),
                 "s.json: camera: eye and target must differ"),
      scene_case("scene: fovy 0", with("\"fovy_deg\":45", "\"fovy_deg\":0"),
                 "s.json: camera.fovy_deg: must be"),
      scene_case("scene: fovy 180", with("\"fovy_deg\":45", "\"fovy_deg\":180"),
                 "s.json: camera.fovy_deg: must be"),
      scene_case("scene: near 0", with("\"near\":0.1", "\"near\":0"), "s.json: camera.near: must"),
      scene_case("scene: far below near", with("\"far\":100", "\"far\":0.01"),
                 "s.json: camera.far: must"),
      scene_case("scene: meshes missing", R"({"width":8,"height":8,)" + kCamera + "}",
                 "s.json: meshes: missing"),
      scene_case("scene: meshes object", scene_text("{}"), "s.json: meshes: expected an array"),
      scene_case("scene: mesh entry array", scene_text("[[1]]"),
                 "s.json: meshes[0]: expected an object"),
      scene_case("scene: obj and gltf", scene_text(R"([{"obj":"m.obj","gltf":"m.obj"}])"),
                 "s.json: meshes[0]: give either"),
      scene_case("scene: no mesh path", scene_text(R"([{"color":[1,0,0]}])"),
                 "s.json: meshes[0]: needs"),
      scene_case("scene: mesh path number", scene_text(R"([{"obj":7}])"),
                 "s.json: meshes[0].obj: expected a file path"),
      scene_case("scene: mesh path empty", scene_text(R"([{"obj":""}])"),
                 "s.json: meshes[0].obj: expected a file path"),
      scene_case("scene: mesh path with NUL", scene_text(R"([{"obj":"m.obj\u0000.txt"}])"),
                 "s.json: meshes[0].obj: the path contains a NUL byte"),
      scene_case("scene: mesh file missing", scene_text(R"([{"obj":"nope.obj"}])"),
                 "s.json: meshes[0]: cannot open 'nope.obj'"),
      scene_case("scene: mesh path a directory", scene_text(R"([{"obj":"."}])"),
                 "s.json: meshes[0]: cannot open '.': Is a directory"),
      scene_case("scene: mesh /dev/zero", scene_text(R"([{"obj":"/dev/zero"}])"),
                 "s.json: meshes[0]: cannot open '/dev/zero': not a regular file"),
      scene_case("scene: model 3 numbers", scene_text(R"([{"obj":"m.obj","model":[1,2,3]}])"),
                 "s.json: meshes[0].model: expected 4 rows"),
      scene_case("scene: model last row",
                 scene_text(R"([{"obj":"m.obj","model":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,1]}])"),
                 "s.json: meshes[0].model: last row"),
      strict(scene_case(
                 "scene: model 1e308 culls everything",
                 scene_text(
                     R"([{"obj":"m.obj","model":[1e308,0,0,0,0,1e308,0,0,0,0,1e308,0,0,0,0,1]}])"),
                 ""),
             "s.json: meshes[0]: the mesh lies outside the finite range"),
      scene_case("scene: color component 2", scene_text(R"([{"obj":"m.obj","color":[2,0,0]}])"),
                 "s.json: meshes[0].color[0]: colour component"),
      scene_case("scene: color word", scene_text(R"([{"obj":"m.obj","color":"blue"}])"),
                 "s.json: meshes[0].color: expected"),
      scene_case("scene: background two numbers",
                 scene_text(R"([{"obj":"m.obj"}])", kCamera, R"(,"background":[1,0])"),
                 "s.json: background: expected [r,g,b]"),
      scene_case("scene: lights object",
                 scene_text(R"([{"obj":"m.obj"}])", kCamera, R"(,"lights":{"type":"point"})"),
                 "s.json: lights: expected an array"),
      scene_case("scene: too many lights",
                 scene_text(R"([{"obj":"m.obj"}])", kCamera,
                            [] {
                              std::string lights = R"(,"lights":[)";
                              for (std::uint64_t i = 0; i <= covrast::kMaxSceneLights; ++i) {
                                lights += i == 0 ? "" : ",";
                                lights += R"({"type":"ambient"})";
                              }
                              return lights + "]";
                            }()),
                 "s.json: lights: 1025 lights, more than 1024 (docs/limits.md)"),
      scene_case("scene: light type",
                 scene_text(R"([{"obj":"m.obj"}])", kCamera, R"(,"lights":[{"type":"laser"}])"),
                 "s.json: lights[0].type: expected"),
      scene_case("scene: light direction zero",
                 scene_text(R"([{"obj":"m.obj"}])", kCamera,
                            R"(,"lights":[{"type":"directional","direction":[0,0,0]}])"),
                 "s.json: lights[0].direction: must not be zero"),
      scene_case(
          "scene: spot cone reversed",
          scene_text(
              R"([{"obj":"m.obj"}])", kCamera,
              R"(,"lights":[{"type":"spot","direction":[0,0,-1],"position":[0,0,1],"inner_cone_deg":50,"outer_cone_deg":40}])"),
          "s.json: lights[0].outer_cone_deg: must be greater"),
      scene_case("scene: metallic 2", scene_text(R"([{"obj":"m.obj","material":{"metallic":2}}])"),
                 "s.json: meshes[0].material.metallic: expected a number in 0..1"),
      scene_case("scene: normals word", scene_text(R"([{"obj":"m.obj","normals":"bumpy"}])"),
                 "s.json: meshes[0].normals: expected"),
      scene_case("scene: file normals missing", scene_text(R"([{"obj":"m.obj","normals":"file"}])"),
                 "s.json: meshes[0].normals: \"file\" but 'm.obj' has no normals"),
      scene_case("scene: vertex colours missing",
                 scene_text(R"([{"obj":"m.obj","color":"vertex"}])"),
                 "s.json: meshes[0].color: \"vertex\" but 'm.obj' has no vertex colours"),
      scene_case("scene: camera from glTF without glTF",
                 scene_text(R"([{"obj":"m.obj"}])", R"("camera":{"gltf":0})"),
                 "s.json: camera.gltf: the scene has no glTF mesh"),
      scene_case("scene: unterminated comment", "/* " + good, "s.json:1:"),
      scene_case("scene: broken UTF-8 in a string", with("m.obj", "m\xff.obj"), "s.json:1:"),
      scene_case("scene: unknown mesh extension", scene_text(R"([{"obj":"m.stl"}])"),
                 "s.json: meshes[0]: cannot open 'm.stl'"),
      {"scene: file is a directory", {}, {"render", ".", "-o", "out.png"}, 2, ".: cannot open: "},
      {"scene: file missing",
       {},
       {"render", "nope.json", "-o", "out.png"},
       2,
       "nope.json: cannot open: No such file"},
      {"scene: file is a FIFO",
       {},
       {"render", "pipe", "-o", "out.png"},
       2,
       "pipe: cannot open: not a regular file",
       "pipe"},
      {"scene: /dev/zero",
       {},
       {"render", "/dev/zero", "-o", "out.png"},
       2,
       "/dev/zero: cannot open: not a regular file"},
      {"scene: OBJ mesh is a FIFO",
       {{"s.json", scene_text(R"([{"obj":"p.obj"}])")}},
       render_args(),
       2,
       "s.json: meshes[0]: cannot open 'p.obj': not a regular file",
       "p.obj"},
      {"scene: glTF mesh is a FIFO",
       {{"s.json", scene_text(R"([{"gltf":"p.gltf"}])")}},
       render_args(),
       2,
       "s.json: meshes[0]: cannot open 'p.gltf': not a regular file",
       "p.gltf"},
  };
  return cases;
}

}  // namespace

namespace {

std::vector<Case> obj_cases() {
  std::string binary =
      "\x7f"
      "ELF";
  binary += std::string(64, '\0');
  std::string long_face = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf";
  for (std::uint64_t i = 0; i <= covrast::kMaxObjFaceCorners; ++i) long_face += " 1";
  long_face += "\n";
  return {
      obj_case("obj: binary data", binary, "m.obj: binary data"),
      obj_case("obj: NUL bytes only", std::string(4096, '\0'), "m.obj: binary data"),
      obj_case("obj: a glb", make_glb("{}", ""), "m.obj: binary glTF"),
      obj_case("obj: JSON", R"({"asset":{"version":"2.0"}})", "m.obj: JSON, not an OBJ file"),
      obj_case("obj: JSON array after BOM", "\xEF\xBB\xBF  [1,2]", "m.obj: JSON, not an OBJ file"),
      obj_case("obj: bad number", "v 0 x 0\n", "m.obj:1: bad number 'x'"),
      obj_case("obj: vertex with two numbers", "v 0 0\n", "m.obj:1: vertex needs x y z"),
      obj_case("obj: normal with two numbers", "vn 0 1\n", "m.obj:1: normal needs x y z"),
      obj_case("obj: face index 0", kTriangleObj + "f 0 1 2\n", "m.obj:5: face index 0"),
      obj_case("obj: face index past the end", kTriangleObj + "f 1 2 9\n",
               "m.obj:5: face index 9 out of range"),
      obj_case("obj: face index huge", kTriangleObj + "f 1 2 99999999999\n", "m.obj:5: face index"),
      obj_case("obj: face index too negative", kTriangleObj + "f -1 -2 -4\n",
               "m.obj:5: face index -4"),
      obj_case("obj: face of two corners", kTriangleObj + "f 1 2\n",
               "m.obj:5: face needs at least 3 vertices"),
      obj_case("obj: face word", kTriangleObj + "f a b c\n", "m.obj:5: bad face vertex 'a'"),
      obj_case("obj: face normal index word", kTriangleObj + "f 1//x 2//x 3//x\n",
               "m.obj:5: bad face vertex"),
      obj_case("obj: face of too many corners", long_face,
               "m.obj:4: face has more than " + std::to_string(covrast::kMaxObjFaceCorners)),
      obj_case("obj: empty file", "", "m.obj: no triangles: the mesh draws nothing", true),
      obj_case("obj: comments only", "# nothing\n# here\n",
               "m.obj: no triangles: the mesh draws nothing", true),
      obj_case("obj: a text file", "This is not a mesh.\nJust words.\n",
               "m.obj: no triangles: the mesh draws nothing", true),
      obj_case("obj: NaN vertex", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
               "m.obj: dropped 1 triangles with NaN/Inf coordinates", true),
      obj_case("obj: vertices without faces", "v 0 0 0\nv 1 0 0\n",
               "m.obj: no triangles: the mesh draws nothing", true),
  };
}

std::vector<Case> gltf_cases() {
  const auto with = [](const std::function<void(json&)>& edit) { return edited_gltf(edit); };
  const std::string instancing = [] {
    GltfBuilder builder = triangle_gltf();
    builder.gltf["accessors"].push_back(
        {{"componentType", 5126}, {"count", covrast::kMaxGltfInstances + 1}, {"type", "VEC3"}});
    builder.gltf["nodes"][0]["extensions"] = {
        {"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", 1}}}}}};
    builder.gltf["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    return builder.gltf_text();
  }();
  std::string deep_extras = with([](json& d) { d["asset"]["extras"] = 0; });
  const std::string marker = R"("extras":0)";
  deep_extras.replace(deep_extras.find(marker), marker.size(), "\"extras\":" + nested(50000, "0"));
  std::string overflow = with([](json& d) { d["asset"]["extras"] = 12345; });
  overflow.replace(overflow.find("12345"), 5, "1e400");
  const std::string depth_text = std::to_string(covrast::kMaxJsonDepth);
  // Issue 28: a skinned triangle whose JOINTS_0 are floats of -1e10 (was a segfault).
  const std::string float_joints = [] {
    GltfBuilder builder = triangle_gltf();
    const int joints =
        builder.add_floats({-1e10f, 0, 0, 0, -1e10f, 0, 0, 0, -1e10f, 0, 0, 0}, "VEC4");
    const int weights = builder.add_floats({1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, "VEC4");
    builder.gltf["scenes"][0]["nodes"] = {0, 1};
    builder.gltf["nodes"] = {{{"mesh", 0}, {"skin", 0}}, json::object()};
    builder.gltf["skins"] = json::array({{{"joints", {1}}}});
    builder.gltf["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = joints;
    builder.gltf["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = weights;
    return builder.gltf_text();
  }();
  // Issue 28: a textured triangle (a 2x2 PNG as a data: URI); `edit` changes it.
  const auto textured = [](const std::function<void(json&)>& edit) {
    GltfBuilder builder = triangle_gltf();
    const int uv = builder.add_floats({0, 0, 1, 0, 0, 1}, "VEC2");
    builder.gltf["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = uv;
    builder.gltf["meshes"][0]["primitives"][0]["material"] = 0;
    builder.gltf["materials"] =
        json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
    builder.gltf["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
    builder.gltf["samplers"] = json::array({json::object()});
    const std::string png = good_png(2, 2);
    builder.gltf["images"] =
        json::array({{{"uri", "data:image/png;base64," + covrast::test::base64(png)}}});
    edit(builder.gltf);
    return builder.gltf_text();
  };
  const std::string sparse_unsorted = [] {
    GltfBuilder builder = triangle_gltf();
    std::string indices;
    covrast::test::put_u16(indices, 2);
    covrast::test::put_u16(indices, 1);
    const int index_view = builder.add_view(indices);
    std::string values;
    for (int k = 0; k < 6; ++k) covrast::test::put_f32(values, 0.5f);
    const int value_view = builder.add_view(values);
    builder.gltf["accessors"][0]["sparse"] = {
        {"count", 2},
        {"indices", {{"bufferView", index_view}, {"componentType", 5123}}},
        {"values", {{"bufferView", value_view}}}};
    return builder.gltf_text();
  }();
  const auto with_light = [](const std::string& type) {
    GltfBuilder builder = triangle_gltf();
    builder.gltf["extensionsUsed"] = json::array({"KHR_lights_punctual"});
    // json::array: a braced list of one element is an array for g++ but a copy of the
    // element for clang (nlohmann::json's initializer-list constructor).
    builder.gltf["extensions"] = {
        {"KHR_lights_punctual", {{"lights", json::array({{{"type", type}, {"range", 0}}})}}}};
    builder.gltf["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
    return builder.gltf_text();
  };
  return {
      gltf_case("gltf: sampler magFilter 1234",
                textured([](json& d) { d["samplers"][0]["magFilter"] = 1234; }),
                "m.gltf: material 0 baseColorTexture: sampler 0: magFilter 1234 is not 9728 "
                "(NEAREST) or 9729 (LINEAR)"),
      gltf_case("gltf: sampler minFilter 9730",
                textured([](json& d) { d["samplers"][0]["minFilter"] = 9730; }),
                "m.gltf: material 0 baseColorTexture: sampler 0: minFilter 9730 is not"),
      gltf_case("gltf: sampler wrapT 0", textured([](json& d) { d["samplers"][0]["wrapT"] = 0; }),
                "m.gltf: material 0 baseColorTexture: sampler 0: wrapT 0 is not 33071, 33648 or "
                "10497"),
      gltf_case("gltf: texture transform texCoord 1e30", textured([](json& d) {
                  d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
                      {"KHR_texture_transform", {{"texCoord", 1e30}}}};
                }),
                "m.gltf: material 0 baseColorTexture: texCoord 1e+30 (covrast reads TEXCOORD_0 "
                "and TEXCOORD_1)"),
      gltf_case("gltf: texture transform offset a string", textured([](json& d) {
                  d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = {
                      {"KHR_texture_transform", {{"offset", "1"}}}};
                }),
                "m.gltf: material 0 baseColorTexture: KHR_texture_transform.offset: expected an "
                "array of 2 numbers"),
      gltf_case("gltf: image uri with %00",
                textured([](json& d) { d["images"][0]["uri"] = "s.json%00.png"; }),
                "m.gltf: image 0 (s.json%00.png): the path contains a NUL byte"),
      gltf_case("gltf: image data: URI of text/html",
                textured([](json& d) { d["images"][0]["uri"] = "data:text/html;base64,PGI+"; }),
                "m.gltf: image 0: data: URI of media type 'text/html' (expected image/png, "
                "image/jpeg or application/octet-stream)"),
      gltf_case("gltf: alphaCutoff -1 in MASK mode", textured([](json& d) {
                  d["materials"][0]["alphaMode"] = "MASK";
                  d["materials"][0]["alphaCutoff"] = -1;
                }),
                "m.gltf: material 0: alphaCutoff -1 must be >= 0"),
      gltf_case("gltf: alphaCutoff -1 unused",
                textured([](json& d) { d["materials"][0]["alphaCutoff"] = -1; }),
                "m.gltf: material 0: alphaCutoff -1 must be >= 0 (ignored: alphaMode is OPAQUE)",
                "m.gltf", true),
      gltf_case("gltf: sparse indices unsorted", sparse_unsorted,
                "m.gltf: mesh 0 primitive 0 POSITION: sparse indices must strictly increase (2 "
                "then 1)"),
      gltf_case("gltf: point light range 0", with_light("point"),
                "m.gltf: KHR_lights_punctual lights[0].range: expected a number > 0, got 0"),
      gltf_case("gltf: directional light range 0", with_light("directional"),
                "m.gltf: KHR_lights_punctual lights[0].range: expected a number > 0, got 0 "
                "(ignored: a directional light has no range)",
                "m.gltf", true),
      gltf_case("gltf: skin joints of -1e10 as FLOAT", float_joints,
                "m.gltf: mesh 0 primitive 0: JOINTS_0 (accessor 1) has component type 5126: "
                "joints must be UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123)"),
      gltf_case("gltf: not JSON", "hello", "m.gltf: not a glTF file"),
      gltf_case("gltf: empty file", "", "m.gltf: not a glTF file"),
      gltf_case("gltf: an OBJ", kTriangleObj, "m.gltf: not a glTF file"),
      gltf_case("gltf: a PNG", good_png(2, 2), "m.gltf: not a glTF file"),
      gltf_case("gltf: JSON array", "[1]", "m.gltf: not a glTF file"),
      gltf_case("gltf: truncated JSON", triangle_gltf().gltf_text().substr(0, 40),
                "m.gltf:1:41: syntax error while parsing object key"),
      gltf_case("gltf: deep extras", deep_extras,
                "m.gltf: arrays and objects nested deeper than " + depth_text),
      gltf_case("gltf: number overflow", overflow, "m.gltf: a number beyond the range"),
      gltf_case("gltf: empty object", "{}", "m.gltf: JSON string too short"),
      gltf_case("gltf: asset only", R"({"asset":{"version":"2.0"}})",
                "m.gltf: no triangles: the mesh draws nothing", "m.gltf", true),
      gltf_case("gltf: no scenes nor nodes", with([](json& d) {
                  d.erase("scenes");
                  d.erase("nodes");
                }),
                "m.gltf: no triangles: the mesh draws nothing", "m.gltf", true),
      gltf_case("gltf: accessors an object", with([](json& d) { d["accessors"] = json::object(); }),
                "m.gltf: accessors: expected an array"),
      gltf_case("gltf: meshes a string", with([](json& d) { d["meshes"] = "mesh"; }),
                "m.gltf: meshes: expected an array"),
      gltf_case("gltf: node an array", with([](json& d) { d["nodes"][0] = json::array(); }),
                "m.gltf: nodes[0]: expected an object"),
      gltf_case("gltf: count a string", with([](json& d) { d["accessors"][0]["count"] = "3"; }),
                "m.gltf: accessors[0].count: expected an integer >= 0"),
      gltf_case("gltf: count negative", with([](json& d) { d["accessors"][0]["count"] = -3; }),
                "m.gltf: accessors[0].count: expected an integer >= 0"),
      gltf_case("gltf: count fractional", with([](json& d) { d["accessors"][0]["count"] = 2.5; }),
                "m.gltf: accessors[0].count: expected an integer >= 0"),
      gltf_case("gltf: bufferView negative",
                with([](json& d) { d["accessors"][0]["bufferView"] = -1; }),
                "m.gltf: accessors[0].bufferView: expected an index"),
      gltf_case("gltf: byteLength a string",
                with([](json& d) { d["bufferViews"][0]["byteLength"] = "36"; }),
                "m.gltf: bufferViews[0].byteLength: expected an integer >= 0"),
      gltf_case("gltf: primitives an object",
                with([](json& d) { d["meshes"][0]["primitives"] = json::object(); }),
                "m.gltf: meshes[0].primitives: expected an array"),
      gltf_case("gltf: attributes an array",
                with([](json& d) { d["meshes"][0]["primitives"][0]["attributes"] = {0}; }),
                "m.gltf: meshes[0].primitives[0].attributes: expected an object"),
      gltf_case("gltf: node mesh a string", with([](json& d) { d["nodes"][0]["mesh"] = "0"; }),
                "m.gltf: nodes[0].mesh: expected an index"),
      gltf_case("gltf: scene nodes strings", with([](json& d) { d["scenes"][0]["nodes"] = {"0"}; }),
                "m.gltf: scenes[0].nodes: expected an array of indices"),
      // Issue 26: what the Khronos validator calls errors, each named by its JSON path (the
      // fields covrast uses) or a warning that --strict makes an error (one it ignores).
      gltf_case(
          "gltf: normalTexture.scale a string", with([](json& d) {
            d["materials"] = json::array({{{"normalTexture", {{"index", 0}, {"scale", "1"}}}}});
          }),
          "m.gltf: materials[0].normalTexture.scale: expected a number, got \"1\""),
      gltf_case("gltf: texture index -1", with([](json& d) {
                  d["materials"] = json::array(
                      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", -1}}}}}}});
                }),
                "m.gltf: materials[0].pbrMetallicRoughness.baseColorTexture.index: expected an "
                "index (an integer >= 0), got -1"),
      gltf_case("gltf: baseColorFactor of three numbers", with([](json& d) {
                  d["materials"] =
                      json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1}}}}}});
                }),
                "m.gltf: materials[0].pbrMetallicRoughness.baseColorFactor: expected 4 numbers, "
                "got 3"),
      gltf_case("gltf: emissiveFactor a number", with([](json& d) {
                  d["materials"] = json::array({{{"emissiveFactor", 1}}});
                }),
                "m.gltf: materials[0].emissiveFactor: expected an array of numbers, got 1"),
      gltf_case("gltf: texture source a string", with([](json& d) {
                  d["textures"] = json::array({{{"source", "0"}}});
                }),
                "m.gltf: textures[0].source: expected an index"),
      gltf_case("gltf: mesh name a number", with([](json& d) { d["meshes"][0]["name"] = 7; }),
                "m.gltf: meshes[0].name: expected a string, got 7 (ignored)", "m.gltf", true),
      gltf_case("gltf: matrix of strings",
                with([](json& d) { d["nodes"][0]["matrix"] = json::array({"1"}); }),
                "m.gltf: nodes[0].matrix: expected an array of numbers"),
      gltf_case("gltf: 67 million elements without a bufferView", with([](json& d) {
                  d["accessors"][0].erase("bufferView");
                  d["accessors"][0]["count"] = 67108864;
                }),
                "m.gltf: mesh 0 primitive 0 POSITION: accessor 0 has 67108864 elements, more than "
                "the 16777216 covrast reads"),
      gltf_case(
          "gltf: instanced past the limit", instancing,
          "m.gltf: node 0: EXT_mesh_gpu_instancing: TRANSLATION gives 1048577 instances, more "
          "than 1048576"),
      gltf_case("gltf: data URI without base64", with([](json& d) {
                  d["buffers"][0]["uri"] = "data:application/octet-stream,AAAA";
                }),
                "m.gltf: buffers[0]: a data: URI without ';base64,'"),
      gltf_case("gltf: data URI of another type",
                with([](json& d) { d["buffers"][0]["uri"] = "data:foo/bar;base64,AAAA"; }),
                "m.gltf: buffers[0]: data: URI of media type 'foo/bar'"),
      gltf_case("gltf: byteLength larger than the data",
                with([](json& d) { d["buffers"][0]["byteLength"] = 4000; }),
                "m.gltf: buffers[0]: its data: URI decodes to 36 bytes, its byteLength says 4000"),
      gltf_case("gltf: byteLength missing",
                with([](json& d) { d["buffers"][0].erase("byteLength"); }),
                "m.gltf: buffers[0]: byteLength missing"),
      gltf_case("gltf: buffer file missing",
                with([](json& d) { d["buffers"][0]["uri"] = "missing.bin"; }),
                "m.gltf: buffers[0]: cannot open 'missing.bin'"),
      gltf_case("gltf: buffer file a directory",
                with([](json& d) { d["buffers"][0]["uri"] = "."; }),
                "m.gltf: buffers[0]: cannot open '.': Is a directory"),
      gltf_case("gltf: buffer /dev/zero",
                with([](json& d) { d["buffers"][0]["uri"] = "/dev/zero"; }),
                "m.gltf: buffers[0]: cannot open '/dev/zero': not a regular file"),
      gltf_case("gltf: buffer URI with NUL",
                with([](json& d) { d["buffers"][0]["uri"] = std::string("m.gltf\0x", 8); }),
                "m.gltf: buffers[0]: 'm.gltf?x': the path contains a NUL byte"),
      gltf_case("gltf: buffer file of another size",
                with([](json& d) { d["buffers"][0]["uri"] = "s.json"; }),
                "m.gltf: buffers[0]: 's.json' holds "),
      {"gltf: buffer file a FIFO",
       {{"s.json", scene_text(R"([{"gltf":"m.gltf"}])")},
        {"m.gltf", edited_gltf([](json& d) { d["buffers"][0]["uri"] = "b.bin"; })}},
       render_args(),
       2,
       "m.gltf: buffers[0]: cannot open 'b.bin': not a regular file",
       "b.bin"},
      gltf_case("gltf: required extension unknown",
                with([](json& d) { d["extensionsRequired"] = {"KHR_teleport"}; }),
                "m.gltf: requires the glTF extension KHR_teleport"),
      gltf_case("gltf: node mesh out of range", with([](json& d) { d["nodes"][0]["mesh"] = 7; }),
                "m.gltf: node 0: mesh 7 does not exist"),
      gltf_case("gltf: primitive mode 9",
                with([](json& d) { d["meshes"][0]["primitives"][0]["mode"] = 9; }),
                "m.gltf: mesh 0 primitive 0: unknown mode 9"),
      gltf_case("gltf: bufferView out of range",
                with([](json& d) { d["accessors"][0]["bufferView"] = 5; }),
                "m.gltf: mesh 0 primitive 0 POSITION: bufferView 5 does not exist"),
      gltf_case("gltf: accessor past its view",
                with([](json& d) { d["accessors"][0]["count"] = 30; }),
                "m.gltf: mesh 0 primitive 0 POSITION: accessor reads past the end of bufferView 0"),
      gltf_case("gltf: node its own child", with([](json& d) { d["nodes"][0]["children"] = {0}; }),
                "m.gltf: node 0 is reached twice"),
      gltf_case("gltf: scene index out of range", with([](json& d) { d["scene"] = 3; }),
                "m.gltf: scene 3 does not exist"),
      gltf_case("gltf: indices accessor missing",
                with([](json& d) { d["meshes"][0]["primitives"][0]["indices"] = 9; }),
                "m.gltf: primitive indices accessor out of bounds"),
      gltf_case("gltf: points only",
                with([](json& d) { d["meshes"][0]["primitives"][0]["mode"] = 0; }),
                "m.gltf: 1 primitives not drawn", "m.gltf", true),
  };
}

std::vector<Case> glb_cases() {
  const std::string good = triangle_gltf().glb();
  std::string bad_version = good;
  bad_version[4] = 7;
  std::string bad_length = good;
  bad_length[8] = static_cast<char>(bad_length[8] + 4);
  std::string long_chunk = good;
  long_chunk[13] = 0x7f;
  std::string not_json_chunk = good;
  not_json_chunk[16] = 'X';
  std::string deep = "{\"asset\":{\"version\":\"2.0\",\"extras\":" + nested(20000, "0") + "}}";
  return {
      gltf_case("glb: magic only", "glTF",
                "m.glb: binary glTF of 4 bytes: too short for its header and JSON chunk", "m.glb"),
      gltf_case("glb: header only", good.substr(0, 12), "m.glb: binary glTF of 12 bytes", "m.glb"),
      gltf_case("glb: truncated", good.substr(0, good.size() / 2),
                "m.glb: binary glTF header says " + std::to_string(good.size()) +
                    " bytes, the "
                    "file has " +
                    std::to_string(good.size() / 2) + " (truncated or padded)",
                "m.glb"),
      gltf_case("glb: version 7", bad_version,
                "m.glb: binary glTF version 7 (covrast reads version 2)", "m.glb"),
      gltf_case(
          "glb: version 1",
          [&] {
            std::string v1 = good;
            v1[4] = 1;
            return v1;
          }(),
          "m.glb: binary glTF version 1", "m.glb"),
      gltf_case("glb: length field wrong", bad_length, "m.glb: binary glTF header says ", "m.glb"),
      gltf_case("glb: JSON chunk too long", long_chunk, "m.glb: binary glTF JSON chunk of ",
                "m.glb"),
      gltf_case("glb: first chunk not JSON", not_json_chunk,
                "m.glb: binary glTF whose first chunk is not JSON", "m.glb"),
      gltf_case("glb: deep extras", make_glb(deep, ""), "m.glb: arrays and objects nested deeper",
                "m.glb"),
      gltf_case("glb: BIN chunk empty", make_glb(triangle_gltf().gltf.dump(), ""),
                "m.glb: Insufficient storage space for Chunk1(BIN data)", "m.glb"),
      gltf_case("glb: wrong types", edited_glb([](json& d) { d["nodes"] = "all"; }),
                "m.glb: nodes: expected an array", "m.glb"),
      gltf_case("glb: garbage after magic", "glTF" + std::string(100, '\xAB'),
                "m.glb: binary glTF version ", "m.glb"),
      gltf_case(
          "glb: BIN chunk short",
          [&] {
            std::string cut = good.substr(0, good.size() - 8);
            std::string length;
            put_u32(length, static_cast<std::uint32_t>(cut.size()));
            return cut.replace(8, 4, length);
          }(),
          "m.glb: binary glTF BIN chunk of 36 bytes runs past the end of the file", "m.glb"),
  };
}

std::vector<Case> png_cases() {
  const std::string good = good_png(4, 4);
  std::string huge = png_header(16000, 16000);
  put_chunk(huge, "IEND", "");
  std::string enormous = png_header(100000, 100000);
  put_chunk(enormous, "IEND", "");
  std::string no_idat = png_header(4, 4);
  put_chunk(no_idat, "IEND", "");
  std::string empty_idat = png_header(4, 4);
  put_chunk(empty_idat, "IDAT", "");
  put_chunk(empty_idat, "IEND", "");
  std::string bad_crc = good;
  bad_crc[29] = static_cast<char>(bad_crc[29] ^ 1);  // inside IHDR's CRC
  // Issue 28: the CRC of the last IDAT chunk (the 4 bytes before IEND's 12) was not checked.
  std::string bad_idat_crc = good;
  const std::size_t iend = bad_idat_crc.size() - 12;
  bad_idat_crc[iend - 1] = static_cast<char>(bad_idat_crc[iend - 1] ^ 1);
  const std::string pixels = std::to_string(covrast::kMaxPngPixels);
  return {
      compare_case("png: IDAT CRC wrong", bad_idat_crc,
                   "a.png: cannot read PNG: invalid chunk checksum"),
      compare_case("png: not a PNG", "hello", "a.png: cannot read PNG: not a PNG file"),
      compare_case("png: empty", "", "a.png: cannot read PNG: not a PNG file"),
      compare_case("png: signature only", kPngSignature,
                   "a.png: cannot read PNG: truncated: the file ends before the image does"),
      compare_case("png: truncated in IHDR", good.substr(0, 20),
                   "a.png: cannot read PNG: truncated: the file ends before the image does"),
      compare_case("png: truncated in IDAT", good.substr(0, good.size() - 20),
                   "a.png: cannot read PNG: truncated: the file ends before the image does"),
      compare_case("png: no IDAT", no_idat, "a.png: cannot read PNG: invalid chunk position"),
      compare_case("png: empty IDAT", empty_idat, "a.png: cannot read PNG: IDAT stream too short"),
      compare_case("png: IHDR CRC wrong", bad_crc,
                   "a.png: cannot read PNG: invalid chunk checksum"),
      compare_case("png: 16000x16000 header", huge,
                   "a.png: cannot read PNG: 16000x16000 is more than the " + pixels),
      compare_case("png: 100000x100000 header", enormous,
                   "a.png: cannot read PNG: a side over the 16384 pixels covrast reads"),
      compare_case("png: sizes differ", good_png(5, 4),
                   "a.png is 5x4 but b.png is 4x4: compare needs images of the same size"),
      compare_case("png: a JPEG", std::string("\xFF\xD8\xFF\xE0", 4) + std::string(64, '\0'),
                   "a.png: cannot read PNG: not a PNG file"),
      {"png: a directory",
       {{"b.png", good}},
       {"compare", ".", "b.png"},
       2,
       ".: cannot read PNG: Is a directory"},
      {"png: a FIFO",
       {{"b.png", good}},
       {"compare", "p.png", "b.png"},
       2,
       "p.png: cannot read PNG: not a regular file",
       "p.png"},
      {"png: /dev/zero",
       {{"b.png", good}},
       {"compare", "/dev/zero", "b.png"},
       2,
       "/dev/zero: cannot read PNG: not a regular file"},
      {"png: missing",
       {{"b.png", good}},
       {"compare", "nope.png", "b.png"},
       2,
       "nope.png: cannot read PNG: No such file"},
  };
}

std::vector<Case> manifest_cases() {
  const std::string good_case = R"({"name":"c","scene":"s.json","golden":"g.png"})";
  const auto manifest = [](const std::string& cases) { return R"({"cases":[)" + cases + "]}"; };
  return {
      manifest_case(
          "manifest: not JSON", "cases",
          "t.json: malformed manifest JSON: parse error at line 1, column 1: syntax error"),
      manifest_case(
          "manifest: empty", "",
          "t.json: malformed manifest JSON: parse error at line 1, column 1: syntax error"),
      manifest_case("manifest: top level array", "[]", "t.json: manifest: must be a JSON object"),
      manifest_case("manifest: cases missing", "{}", "t.json: manifest: \"cases\" must be"),
      manifest_case("manifest: cases object", R"({"cases":{}})",
                    "t.json: manifest: \"cases\" must be"),
      manifest_case("manifest: unknown key", R"({"cases":[],"extra":1})",
                    "t.json: manifest: \"extra\" is not a manifest key"),
      manifest_case("manifest: case a number", manifest("7"), "t.json: case 1: must be an object"),
      manifest_case("manifest: case without scene", manifest(R"({"name":"c","golden":"g.png"})"),
                    "t.json: case 'c': \"scene\" is missing"),
      manifest_case("manifest: scene a number",
                    manifest(R"({"name":"c","scene":5,"golden":"g.png"})"),
                    "t.json: case 'c': \"scene\" must be a non-empty string"),
      manifest_case("manifest: scene path with NUL",
                    manifest(R"({"name":"c","scene":"s.json\u0000x","golden":"g.png"})"),
                    "t.json: case 'c': \"scene\" contains a NUL byte"),
      manifest_case("manifest: duplicate names", manifest(good_case + "," + good_case),
                    "t.json: case 2: \"name\" 'c' is used by an earlier case"),
      manifest_case(
          "manifest: number overflow",
          manifest(
              R"({"name":"c","scene":"s.json","golden":"g.png","tolerance":{"max_rmse":1e400}})"),
          "t.json: malformed manifest JSON: number overflow parsing '1e400'"),
      manifest_case(
          "manifest: tolerance out of range",
          manifest(
              R"({"name":"c","scene":"s.json","golden":"g.png","tolerance":{"max_diff":300}})"),
          "t.json: case 'c': tolerance: \"max_diff\" must be in 0..255"),
      manifest_case("manifest: nested 100000 deep", R"({"cases":)" + nested(100000) + "}",
                    "t.json: malformed manifest JSON: arrays and objects nested deeper"),
      manifest_case("manifest: unknown mode",
                    manifest(R"({"name":"c","scene":"s.json","golden":"g.png","mode":"blurry"})"),
                    "t.json: case 'c': \"mode\" "),
      manifest_case("manifest: scene missing",
                    manifest(R"({"name":"c","scene":"nope.json","golden":"g.png"})"),
                    "case 'c': nope.json: cannot open"),
      {"manifest: a FIFO",
       {},
       {"test", "t.json"},
       2,
       "t.json: cannot read manifest: not a regular file",
       "t.json"},
      {"manifest: a directory",
       {},
       {"test", "."},
       2,
       ".: cannot read manifest: not a regular file"},
  };
}

std::vector<Case> output_cases() {
  const std::vector<std::pair<std::string, std::string>> files = {{"s.json", scene_text()},
                                                                  {"m.obj", kTriangleObj}};
  return {
      {"output: under /proc",
       files,
       {"render", "s.json", "-o", "/proc/covrast-out.png"},
       2,
       "/proc/covrast-out.png: cannot write: "},
      {"output: missing directory",
       files,
       {"render", "s.json", "-o", "no/out.png"},
       2,
       "no/out.png: cannot write: directory 'no' does not exist"},
      {"output: wrong extension",
       files,
       {"render", "s.json", "-o", "out.txt"},
       2,
       "out.txt: unsupported output extension '.txt'"},
      {"output: a directory",
       files,
       {"render", "s.json", "-o", "."},
       2,
       ".: unsupported output extension ''"},
      {"output: depth under /proc",
       files,
       {"render", "s.json", "-o", "out.png", "--depth", "/proc/covrast-depth.pfm"},
       2,
       "/proc/covrast-depth.pfm: cannot write: "},
      // Issue 28: a directory to be made where a regular file is was "internal error:
      // filesystem error", exit 1.
      {"output: test --report names a regular file",
       {{"t.json", R"({"cases":[{"name":"c","scene":"s.json","golden":"g.png"}]})"},
        {"s.json", scene_text()},
        {"m.obj", kTriangleObj},
        {"g.png", good_png(8, 8)},
        {"r.txt", "x"}},
       {"test", "t.json", "--report", "r.txt"},
       2,
       "r.txt: cannot create the directory: "},
      {"output: test --artifacts names a regular file",
       {{"t.json", R"({"cases":[{"name":"c","scene":"s.json","golden":"g.png"}]})"},
        {"s.json", scene_text()},
        {"m.obj", kTriangleObj},
        {"g.png", good_png(8, 8)},
        {"a.txt", "x"}},
       {"test", "t.json", "--artifacts", "a.txt"},
       2,
       "a.txt: cannot create the directory: "},
      {"output: test --update of a golden under a regular file",
       {{"t.json", R"({"cases":[{"name":"c","scene":"s.json","golden":"f.txt/g.png"}]})"},
        {"s.json", scene_text()},
        {"m.obj", kTriangleObj},
        {"f.txt", "x"}},
       {"test", "t.json", "--update"},
       2,
       "f.txt: cannot create the directory: "},
      {"output: heatmap under /proc",
       {{"a.png", good_png(4, 4)}, {"b.png", good_png(4, 4)}},
       {"compare", "a.png", "b.png", "--heatmap", "/proc/covrast-heat.png"},
       2,
       "/proc/covrast-heat.png: cannot write: "},
  };
}

}  // namespace
