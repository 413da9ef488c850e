// The README tables rendered from the figures (tools/figures/render.h): number formats and
// units, the two layouts, blocks replaced in place with everything else kept; and every README
// of the repository equal to its rendering from results/figures.json.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

#include "common/error.h"
#include "test/support/test_support.h"
#include "tools/figures/figures.h"
#include "tools/figures/render.h"

namespace kestrel::figures {
namespace {

using nlohmann::json;

json row_entry(const std::string& id, const json& value, const std::string& unit = "") {
  json e = {{"id", id},          {"component", id.substr(0, id.find('.'))},
            {"figure", "ATE RMSE"}, {"data", "TUM fr1_xyz"},
            {"value", value},    {"target", "≤ 1.2 cm"},
            {"command", "`kestrel vo --tum DIR`"}, {"build", "Release"},
            {"date", "2026-11-27"}};
  if (value.is_number()) e["unit"] = unit;
  return e;
}

FigureFile loaded_file(const json& entries) { return parse(json{{"figures", entries}}.dump(), "f.json"); }

TEST(FiguresRender, NumbersAreShortestOrToTheirDigits) {
  EXPECT_EQ(format_number(0.94, std::nullopt), "0.94");
  EXPECT_EQ(format_number(0.63, 3), "0.630");
  EXPECT_EQ(format_number(10.8, 2), "10.80");
  EXPECT_EQ(format_number(2346.0, std::nullopt), "2346");
  EXPECT_EQ(format_number(0.0, std::nullopt), "0");
  EXPECT_EQ(format_number(0.062807, std::nullopt), "0.062807");
  EXPECT_EQ(format_number(0.0001, std::nullopt), "0.0001");
  EXPECT_EQ(format_number(5e-5, std::nullopt), "5e-05");
  EXPECT_EQ(format_number(1e-14, std::nullopt), "1e-14");
  EXPECT_EQ(format_number(-3.5, std::nullopt), "-3.5");
  EXPECT_EQ(format_number(0.14, 3), "0.140");
  EXPECT_EQ(format_number(0.045, 4), "0.0450");
}

TEST(FiguresRender, AValueIsPrintedWithItsUnitAndNote) {
  json percent = row_entry("vo.a.gross", 0.53, "%");
  percent["note"] = "(1 of 190)";
  const FigureFile file = loaded_file(json::array({row_entry("vo.a.ate", 0.94, "cm"), percent, row_entry("vo.a.r", 0.038, "x"),
                                               row_entry("vo.a.deg", 6.0, "deg"), row_entry("vo.a.t", 154, "us"),
                                               row_entry("vo.a.rot", 0.617, "deg/s"), row_entry("vo.a.n", 74),
                                               row_entry("vo.a.text", "byte-identical")}));
  const char* expected[] = {"0.94 cm", "0.53 % (1 of 190)", "0.038×", "6°", "154 µs", "0.617 °/s", "74", "byte-identical"};
  for (size_t i = 0; i < file.figures.size(); ++i) EXPECT_EQ(value_cell(file, file.figures[i]), expected[i]);
  EXPECT_EQ(value_text(file, file.figures[1]), "0.53 %") << "a reference gives the value without its note";
}

TEST(FiguresRender, ReferencesExpandToTheNamedValue) {
  json slam = row_entry("slam.a.ate", 0.93, "cm");
  slam["note"] = "(VO {vo.a.ate})";
  const FigureFile file = loaded_file(json::array(
      {row_entry("vo.a.ate", 0.94, "cm"), slam, row_entry("top.parts.vo", "ATE {vo.a.ate}; `tools/{eval,replay}`")}));
  EXPECT_EQ(value_cell(file, file.figures[1]), "0.93 cm (VO 0.94 cm)");
  EXPECT_EQ(value_cell(file, file.figures[2]), "ATE 0.94 cm; `tools/{eval,replay}`");
}

TEST(FiguresRender, ATableHasOneRowPerFigureInFileOrder) {
  json b = row_entry("vo.b", 2.17, "cm");
  b["data"] = "TUM fr1_rpy";
  b["command"] = "`--world floor|stata`";
  b["target"] = "";
  b["date"] = "";
  json other = row_entry("slam.c", 1.0, "cm");
  json named = row_entry("vo.d", 1.0, "cm");
  named["table"] = "speed";
  const FigureFile file = loaded_file(json::array({row_entry("vo.a", 0.94, "cm"), other, b, named}));
  EXPECT_EQ(render_table(file, "vo", ""),
            "| figure | data | value | target | command | build | date |\n"
            "|---|---|---|---|---|---|---|\n"
            "| ATE RMSE | TUM fr1_xyz | 0.94 cm | ≤ 1.2 cm | `kestrel vo --tum DIR` | Release | 2026-11-27 |\n"
            "| ATE RMSE | TUM fr1_rpy | 2.17 cm | — | `--world floor\\|stata` | Release | — |\n");
  EXPECT_EQ(render_table(file, "vo", "speed"),
            "| figure | data | value | target | command | build | date |\n"
            "|---|---|---|---|---|---|---|\n"
            "| ATE RMSE | TUM fr1_xyz | 1 cm | ≤ 1.2 cm | `kestrel vo --tum DIR` | Release | 2026-11-27 |\n");
  EXPECT_THROW(render_table(file, "mapper", ""), InputError);
}

TEST(FiguresRender, ThePartsTableIsPartReadmeHeadline) {
  json part = row_entry("top.parts.vo", "ATE {vo.a}");
  part["table"] = "parts";
  part["figure"] = "visual odometry";
  part["data"] = "`vo/README.md`";
  const FigureFile file = loaded_file(json::array({row_entry("vo.a", 0.94, "cm"), part}));
  EXPECT_EQ(render_table(file, "top", "parts"),
            "| part | README | headline |\n|---|---|---|\n| visual odometry | `vo/README.md` | ATE 0.94 cm |\n");
}

TEST(FiguresRender, AReadmeKeepsEverythingOutsideItsBlocks) {
  json named = row_entry("vo.b", 2.0, "cm");
  named["table"] = "speed";
  const FigureFile file = loaded_file(json::array({row_entry("vo.a", 0.94, "cm"), named}));
  const std::string readme =
      "# vo\n\ntext | with a pipe\n<!-- figures:begin -->\n| old | table |\n|---|---|\n<!-- figures:end -->\n"
      "between\n<!-- figures:begin speed -->\n<!-- figures:end -->\nend without newline";
  const std::string rendered = render_readme(file, "vo", readme, "vo/README.md");
  EXPECT_EQ(rendered, "# vo\n\ntext | with a pipe\n<!-- figures:begin -->\n" + render_table(file, "vo", "") +
                          "<!-- figures:end -->\nbetween\n<!-- figures:begin speed -->\n" +
                          render_table(file, "vo", "speed") + "<!-- figures:end -->\nend without newline");
  EXPECT_EQ(render_readme(file, "vo", rendered, "vo/README.md"), rendered) << "rendering twice changes nothing";
  EXPECT_TRUE(has_figures_block(readme));
  EXPECT_FALSE(has_figures_block("# no table\n<!-- figures:beginning -->\n"));
}

TEST(FiguresRender, MisplacedMarkersAndMissingBlocksAreErrorsNamingTheLine) {
  const FigureFile file = loaded_file(json::array({row_entry("vo.a", 0.94, "cm")}));
  auto error = [&](const std::string& readme) {
    try {
      render_readme(file, "vo", readme, "vo/README.md");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("a\n<!-- figures:begin -->\nold\n"), "vo/README.md:2: a figures:begin without a figures:end");
  EXPECT_EQ(error("a\n<!-- figures:end -->\n"), "vo/README.md:2: a figures:end without a figures:begin");
  EXPECT_NE(error("<!-- figures:begin -->\n<!-- figures:begin -->\n<!-- figures:end -->\n").find("inside the block"),
            std::string::npos);
  EXPECT_NE(error("<!-- figures:begin -->\n<!-- figures:end -->\n<!-- figures:begin -->\n<!-- figures:end -->\n")
                .find("a second block"),
            std::string::npos);
  EXPECT_NE(error("no block at all\n").find("no figures block for table (unnamed) (figure vo.a"), std::string::npos);
  EXPECT_NE(error("<!-- figures:begin -->\n<!-- figures:end -->\n<!-- figures:begin other -->\n<!-- figures:end -->\n")
                .find("is in table 'other'"),
            std::string::npos);
}

// The repository's READMEs are what `kestrel figures --write` makes of results/figures.json.
TEST(FiguresRender, EveryReadmeTableEqualsItsRendering) {
  const FigureFile file = load((test::source_dir() / "results" / "figures.json").string());
  for (const std::string& component : readme_components()) {
    const std::string& name = readme_path(component);
    const std::string readme = test::read_file(test::source_dir() / name);
    ASSERT_FALSE(readme.empty()) << name;
    EXPECT_EQ(render_readme(file, component, readme, name), readme)
        << name << " differs from results/figures.json: run ./kestrel figures --write";
  }
}

}  // namespace
}  // namespace kestrel::figures
