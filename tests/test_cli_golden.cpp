// Tests of `covrast test` (src/cli/manifest.cpp, golden_*.cpp), the golden-manifest runner, through
// the built executable: missing goldens fail and --update writes them with a record of what
// rendered them; a changed golden fails with its measures, JUnit, JSON, artifacts and HTML report;
// the tolerances; --shard and --filter; and every malformed manifest exits 2 naming the case and
// field, without writing anything.
#include <covrast/image.hpp>
#include <covrast/tools.hpp>

#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "test_cli_run.hpp"
#include "test_tempdir.hpp"

namespace fs = std::filesystem;
using covrast::test::read_text;
using covrast::test::RunResult;
using covrast::test::write_text;

namespace {

/// A folder with two scenes (a triangle and a quad of two triangles) and a manifest over them.
class Workspace : public covrast::test::TempDir {
 public:
  Workspace() : covrast::test::TempDir("covrast-test-golden") {
    write_text(*this / "tri.obj", "v 0 1 0\nv -0.87 -0.5 0\nv 0.87 -0.5 0\nf 1 2 3\n");
    write_text(*this / "quad.obj",
               "v -0.7 -0.6 0\nv 0.7 -0.6 0\nv 0.7 0.6 0\nv -0.7 0.6 0\n"
               "f 1 2 3\nf 1 3 4\n");
    write_text(*this / "tri.json", scene("tri.obj"));
    write_text(*this / "quad.json", scene("quad.obj"));
  }
  static std::string scene(const std::string& obj) {
    return R"({"width": 40, "height": 30, "background": [0.1, 0.1, 0.1],
      "camera": {"eye": [0, 0, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fovy_deg": 45,
                 "near": 0.5, "far": 10},
      "meshes": [{"obj": ")" +
           obj + R"(", "color": [1, 0.5, 0.25]}]})";
  }
  RunResult run(std::vector<std::string> args) const {
    args.insert(args.begin(), "test");
    return covrast::test::run_cli_in(path(), args, true);
  }
};

const char* const kManifest = R"({
  "defaults": {"size": "32x24"},
  "cases": [
    {"name": "tri", "scene": "tri.json", "golden": "goldens/tri.png"},
    {"name": "tri-msaa", "scene": "tri.json", "golden": "goldens/tri-msaa.png", "mode": "msaa:4"},
    {"name": "quad", "scene": "quad.json", "golden": "goldens/quad.png", "size": "40x30"},
    {"name": "later", "scene": "tri.json", "golden": "goldens/later.png", "skip": "not yet"}
  ]
})";

nlohmann::json record_of(const fs::path& golden) {
  for (const covrast::PngText& t : covrast::read_png_text(golden)) {
    if (t.keyword == "covrast") return nlohmann::json::parse(t.text);
  }
  FAIL("no covrast record in " << golden);
  return {};
}

}  // namespace

TEST_CASE("covrast test: missing goldens fail, --update writes them, then all pass",
          "[cli][golden]") {
  Workspace w;
  write_text(w / "m.json", kManifest);
  RunResult r = w.run({"m.json"});
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("FAIL tri: no golden image") != std::string::npos);
  CHECK(r.out.find("run covrast test --update") != std::string::npos);
  CHECK(r.out.find("0 passed, 3 failed, 1 skipped") != std::string::npos);
  CHECK_FALSE(fs::exists(w / "goldens"));

  r = w.run({"m.json", "--update"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("updated tri-msaa") != std::string::npos);
  CHECK(r.out.find("3 goldens updated") != std::string::npos);
  CHECK_FALSE(fs::exists(w / "goldens/later.png"));  // skipped: nothing written
  const nlohmann::json rec = record_of(w / "goldens/tri-msaa.png");
  CHECK(rec["mode"] == "msaa:4");
  CHECK(rec["size"] == "32x24");
  CHECK(rec["covrast"] == COVRAST_VERSION);
  CHECK(record_of(w / "goldens/quad.png")["size"] == "40x30");
  CHECK(covrast::read_png(w / "goldens/quad.png").width == 40);
  // Atomic writes leave no temporary files beside the goldens.
  int files = 0;
  for (const auto& e : fs::directory_iterator(w / "goldens")) files += e.is_regular_file();
  CHECK(files == 3);

  r = w.run({"m.json"});
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("3 passed, 0 failed, 1 skipped") != std::string::npos);
}

TEST_CASE("covrast test: a changed golden fails with its measures and reports", "[cli][golden]") {
  Workspace w;
  write_text(w / "m.json", kManifest);
  REQUIRE(w.run({"m.json", "--update"}).exit_code == 0);
  // One channel of one pixel of tri's golden up by 40/255.
  covrast::Image golden = covrast::read_png(w / "goldens/tri.png");
  golden.pixel(5, 5)[1] = std::uint8_t(golden.pixel(5, 5)[1] + 40);
  covrast::write_png(golden, w / "goldens/tri.png");

  const RunResult r =
      w.run({"m.json", "--junit", "r.xml", "--artifacts", "art", "--report", "rep"});
  INFO(r.out << r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.out.find("FAIL tri: diff 40 > 0") != std::string::npos);
  CHECK(r.out.find("golden: (no record") != std::string::npos);
  CHECK(r.out.find("2 passed, 1 failed, 1 skipped") != std::string::npos);
  // Artifacts of the failing case only: its render and the heat map of the difference.
  CHECK(fs::exists(w / "art/tri.actual.png"));
  CHECK(fs::exists(w / "art/tri.diff.png"));
  CHECK_FALSE(fs::exists(w / "art/quad.actual.png"));
  const covrast::Image heat = covrast::read_png(w / "art/tri.diff.png");
  CHECK(heat.pixel(5, 5)[0] > 0);
  CHECK(heat.pixel(6, 5)[0] == 0);
  // JUnit: one testcase per case, the failure's message, the skip's reason.
  const std::string xml = read_text(w / "r.xml");
  CHECK(xml.find("<testsuite name=\"m\" tests=\"4\" failures=\"1\" errors=\"0\" skipped=\"1\"") !=
        std::string::npos);
  CHECK(xml.find("<testcase name=\"tri\" classname=\"m\"") != std::string::npos);
  CHECK(xml.find("<failure message=\"diff 40 &gt; 0") != std::string::npos);
  CHECK(xml.find("<skipped message=\"not yet\"/>") != std::string::npos);
  // The report: one page, images inline, no external resources.
  const std::string html = read_text(w / "rep/index.html");
  CHECK(html.find("id=\"tri\"") != std::string::npos);
  CHECK(html.find("data:image/png;base64,") != std::string::npos);
  CHECK(html.find("http") == std::string::npos);
  CHECK(html.find("<script src") == std::string::npos);
}

TEST_CASE("covrast test: tolerances, JSON summary, --shard and --filter", "[cli][golden]") {
  Workspace w;
  write_text(w / "m.json", kManifest);
  REQUIRE(w.run({"m.json", "--update"}).exit_code == 0);
  covrast::Image golden = covrast::read_png(w / "goldens/quad.png");
  golden.pixel(20, 15)[0] = std::uint8_t(golden.pixel(20, 15)[0] ^ 1);  // off by one level
  covrast::write_png(golden, w / "goldens/quad.png");
  SECTION("exact by default") {
    const RunResult r = w.run({"m.json", "--json", "--filter", "qu*"});
    CHECK(r.exit_code == 1);
    const nlohmann::json j = nlohmann::json::parse(r.out);
    CHECK(j["failed"] == 1);
    REQUIRE(j["cases"].size() == 1);
    CHECK(j["cases"][0]["name"] == "quad");
    CHECK(j["cases"][0]["diff"] == 1);
    CHECK(j["cases"][0]["pixels"] == 0.0);  // 1/255 is not over 1/255
  }
  SECTION("within a tolerance") {
    std::string m = kManifest;
    m.replace(m.find("\"size\": \"40x30\""), 15,
              "\"size\": \"40x30\", \"tolerance\": {\"max_diff\": 1, \"max_rmse\": 0.01}");
    write_text(w / "m.json", m);
    CHECK(w.run({"m.json"}).exit_code == 0);
  }
  SECTION("shards hold every case once") {
    std::multiset<std::string> seen;
    for (int i = 1; i <= 3; ++i) {
      const RunResult r = w.run({"m.json", "--json", "--shard", std::to_string(i) + "/3"});
      const nlohmann::json summary = nlohmann::json::parse(r.out);
      for (const auto& c : summary["cases"]) seen.insert(c["name"]);
    }
    CHECK(seen == std::multiset<std::string>{"later", "quad", "tri", "tri-msaa"});
  }
}

TEST_CASE("covrast test: malformed manifests exit 2 naming the case and field", "[cli][golden]") {
  Workspace w;
  const auto expect_error = [&](const std::string& manifest, const std::string& expected,
                                std::vector<std::string> extra = {}) {
    write_text(w / "bad.json", manifest);
    extra.insert(extra.begin(), "bad.json");
    const RunResult r = w.run(extra);
    INFO("manifest: " << manifest << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(r.err.rfind("covrast: error: ", 0) == 0);
    CHECK(r.err.find('\n') == r.err.size() - 1);
    CHECK(r.err.find(expected) != std::string::npos);
    CHECK(r.out.empty());
    CHECK_FALSE(fs::exists(w / "goldens"));
  };
  const std::string head =
      R"({"cases": [{"name": "a", "scene": "tri.json", "golden": "goldens/a.png")";
  expect_error(head + R"(, "tolernce": {}}]})", "case 'a': \"tolernce\" is not a manifest key");
  expect_error(R"({"cases": [{"name": "a", "golden": "g.png"}]})",
               "case 'a': \"scene\" is missing");
  // Found by fuzz_manifest: a key or a name holding a newline broke the one-line message.
  expect_error(head + R"(, "gold\nen": 1}]})", "case 'a': \"gold\\nen\" is not a manifest key");
  expect_error(R"({"cases": [{"name": "a\nb", "scene": "tri.json", "golden": "g.png"}]})",
               "case 'a\\nb': \"name\" contains a control character");
  expect_error(R"({"cases": [{"name": "a\tb", "scene": "tri.json", "golden": "g.png"}]})",
               "case 'a\\tb': \"name\" contains a control character");
  expect_error(head + R"(, "mode": "coverage\n"}]})",
               "case 'a': \"mode\" unknown mode 'coverage?'");
  expect_error(head + R"(, "size": "4x4\n"}]})", "case 'a': \"size\"");
  expect_error(head + R"(, "mode": "msaa:3"}]})", "case 'a': \"mode\"");
  expect_error(head + R"(, "size": "0x10"}]})", "case 'a': \"size\"");
  expect_error(head + R"(, "tolerance": {"max_diff": 300}}]})",
               "case 'a': tolerance: \"max_diff\" must be in 0..255");
  expect_error(head + R"(, "tolerance": {"max_pixels": "1%"}}]})",
               "\"max_pixels\" must be a number");
  expect_error(head + "}, " + head.substr(11) + "}]}",
               "case 2: \"name\" 'a' is used by an earlier case");
  expect_error(R"({"cases": [{"name": "a", "scene": "none.json", "golden": "g.png"}]})",
               "case 'a': ");
  expect_error(R"({"defaults": {"mode": 4}, "cases": []})",
               "defaults: \"mode\" must be a non-empty string");
  expect_error(R"({"cases": {}})", "\"cases\" must be an array");
  expect_error(R"({"cases": [)", "malformed manifest JSON");
  expect_error(head + "}]}", "--shard", {"--shard", "4/3"});
  expect_error(head + "}]}", "--all goes with --update", {"--all"});
  const RunResult missing = w.run({"no-such-manifest.json"});
  CHECK(missing.exit_code == 2);
  CHECK(missing.err ==
        "covrast: error: no-such-manifest.json: cannot read manifest: no such file\n");
}
