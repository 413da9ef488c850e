// results/figures.json loaded and validated (tools/figures/figures.h): the repository's own
// file validates, and each way an entry can be wrong is an InputError naming the entry; the
// values and limits in SI units.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "common/error.h"
#include "common/numbers.h"
#include "test/support/figures.h"
#include "test/support/test_support.h"
#include "tools/figures/figures.h"

namespace kestrel::figures {
namespace {

using nlohmann::json;

json entry(const std::string& id, const json& value, const std::string& unit = "cm") {
  json e = {{"id", id},       {"component", id.substr(0, id.find('.'))},
            {"figure", "ATE"}, {"data", "fr1_xyz"},
            {"value", value}, {"target", ""},
            {"command", "kestrel vo"}, {"build", "Release"},
            {"date", "2026-11-27"}};
  if (value.is_number()) e["unit"] = unit;
  return e;
}

std::string file_of(const json& entries) { return json{{"figures", entries}}.dump(); }

// The InputError's message for `text`, or "" if it loads.
std::string error_of(const std::string& text) {
  try {
    parse(text, "f.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string error_of_entry(const json& e) { return error_of(file_of(json::array({e}))); }

TEST(FiguresFile, TheRepositorysFileValidates) {
  const FigureFile file = load((test::source_dir() / "results" / "figures.json").string());
  EXPECT_GT(file.figures.size(), 100u);
  for (const std::string& component : readme_components()) {
    bool any = false;
    for (const Figure& f : file.figures) any = any || f.component == component;
    EXPECT_TRUE(any) << "no figure for " << readme_path(component);
  }
}

TEST(FiguresFile, AValidEntryLoadsWithItsFields) {
  json e = entry("vo.fr1_xyz.ate_rmse", 0.94);
  e["limit"] = {{"max", 1.2}};
  e["digits"] = 2;
  e["note"] = "(session 27)";
  const FigureFile file = parse(file_of(json::array({e})), "f.json");
  ASSERT_EQ(file.figures.size(), 1u);
  const Figure& f = file.figures[0];
  EXPECT_EQ(f.component, "vo");
  EXPECT_EQ(f.table, "");
  ASSERT_TRUE(f.is_number());
  EXPECT_EQ(*f.number, 0.94);
  EXPECT_EQ(f.digits, 2);
  ASSERT_TRUE(f.limit);
  EXPECT_FALSE(f.limit->min);
  EXPECT_EQ(*f.limit->max, 1.2);
  EXPECT_EQ(file.find("vo.fr1_xyz.ate_rmse"), &f);
  EXPECT_EQ(file.find("vo.nothing"), nullptr);
}

TEST(FiguresFile, ValuesAndLimitsConvertToSi) {
  json cm = entry("vo.a.ate", 0.94, "cm");
  cm["limit"] = {{"range", {0.5, 1.2}}};
  const json rot = entry("vo.a.rot", 0.63, "deg/s");
  const json percent = entry("vo.a.gross", 0.53, "%");
  const json micro = entry("vo.a.t", 154, "us");
  const json count = entry("vo.a.n", 74, "");
  const FigureFile file = parse(file_of(json::array({cm, rot, percent, micro, count})), "f.json");
  EXPECT_DOUBLE_EQ(file.figures[0].value_in_si(), 0.0094);
  EXPECT_DOUBLE_EQ(*file.figures[0].limit_in_si()->min, 0.005);
  EXPECT_DOUBLE_EQ(*file.figures[0].limit_in_si()->max, 0.012);
  EXPECT_DOUBLE_EQ(file.figures[1].value_in_si(), 0.63 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(file.figures[2].value_in_si(), 0.0053);
  EXPECT_DOUBLE_EQ(file.figures[3].value_in_si(), 154e-6);
  EXPECT_DOUBLE_EQ(file.figures[4].value_in_si(), 74.0);
  EXPECT_FALSE(file.figures[4].limit_in_si());
}

TEST(FiguresFile, ADuplicateIdIsAnError) {
  const std::string e = error_of(file_of(json::array({entry("vo.a.b", 1.0), entry("vo.a.b", 2.0)})));
  EXPECT_NE(e.find("figures[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("also figures[0]"), std::string::npos) << e;
}

TEST(FiguresFile, AnUnknownUnitIsAnErrorListingTheKnownOnes) {
  const std::string e = error_of_entry(entry("vo.a.b", 1.0, "furlong"));
  EXPECT_NE(e.find("unknown unit 'furlong'"), std::string::npos) << e;
  EXPECT_NE(e.find("\"deg/s\""), std::string::npos) << e;
}

TEST(FiguresFile, AValueThatViolatesItsOwnLimitIsAnError) {
  for (const json& limit : {json{{"max", 0.9}}, json{{"min", 1.0}}, json{{"range", {0.1, 0.5}}}}) {
    json e = entry("vo.a.b", 0.94);
    e["limit"] = limit;
    EXPECT_NE(error_of_entry(e).find("violates its own limit"), std::string::npos) << limit.dump();
  }
  json bounds_on = entry("vo.a.b", 1.2);  // inclusive
  bounds_on["limit"] = {{"range", {1.2, 1.2}}};
  EXPECT_EQ(error_of_entry(bounds_on), "");
}

TEST(FiguresFile, AMalformedLimitIsAnError) {
  for (const json& limit : {json{{"range", {2.0, 1.0}}}, json{{"max", 1.0}, {"min", 0.0}}, json{{"below", 1.0}},
                            json{{"range", {1.0}}}, json{{"max", "1"}}, json(1.0)}) {
    json e = entry("vo.a.b", 0.94);
    e["limit"] = limit;
    EXPECT_NE(error_of_entry(e), "") << limit.dump();
  }
}

TEST(FiguresFile, ATextValueTakesNoUnitDigitsOrLimit) {
  json unit = entry("vo.a.b", "byte-identical");
  unit["unit"] = "cm";
  json digits = entry("vo.a.b", "byte-identical");
  digits["digits"] = 2;
  json limit = entry("vo.a.b", "byte-identical");
  limit["limit"] = {{"max", 1.0}};
  for (const json& e : {unit, digits, limit}) EXPECT_NE(error_of_entry(e), "") << e.dump();
  EXPECT_EQ(error_of_entry(entry("vo.a.b", "byte-identical")), "");
}

TEST(FiguresFile, ANumberNeedsAUnitAndAFiniteValue) {
  json no_unit = entry("vo.a.b", 1.0);
  no_unit.erase("unit");
  EXPECT_NE(error_of_entry(no_unit).find("needs a \"unit\""), std::string::npos);
  EXPECT_NE(error_of(R"({"figures": [{"id": "vo.a.b", "component": "vo", "figure": "f", "data": "", "value": 1e999,
             "unit": "", "target": "", "command": "", "build": "", "date": ""}]})"),
            "");
  json boolean = entry("vo.a.b", true);
  EXPECT_NE(error_of_entry(boolean), "");
}

TEST(FiguresFile, UnknownKeysMissingKeysAndWrongTypesAreErrors) {
  json typo = entry("vo.a.b", 1.0);
  typo["limt"] = {{"max", 2.0}};
  EXPECT_NE(error_of_entry(typo).find("unknown key 'limt'"), std::string::npos);
  for (const char* key : {"id", "component", "figure", "data", "value", "target", "command", "build", "date"}) {
    json missing = entry("vo.a.b", 1.0);
    missing.erase(key);
    EXPECT_NE(error_of_entry(missing), "") << key;
  }
  json wrong = entry("vo.a.b", 1.0);
  wrong["command"] = 3;
  EXPECT_NE(error_of_entry(wrong).find("\"command\" is not a string"), std::string::npos);
  EXPECT_NE(error_of(R"({"figures": [], "extra": 1})").find("unknown key 'extra'"), std::string::npos);
  EXPECT_NE(error_of(R"({"figure": []})"), "");
  EXPECT_NE(error_of("[1, 2"), "");
}

TEST(FiguresFile, TheIdIsDottedAndBeginsWithItsComponent) {
  for (const char* id : {"vo", "vo.", "vo..a", "vo.A", "vo.a b", ".vo.a"}) {
    json e = entry("vo.a", 1.0);
    e["id"] = id;
    EXPECT_NE(error_of_entry(e), "") << id;
  }
  json other = entry("slam.a", 1.0);
  other["component"] = "vo";
  EXPECT_NE(error_of_entry(other).find("does not begin with its component"), std::string::npos);
  json unknown = entry("nowhere.a", 1.0);
  EXPECT_NE(error_of_entry(unknown).find("unknown component 'nowhere'"), std::string::npos);
}

TEST(FiguresFile, DatesAreIsoOrEmpty) {
  for (const char* date : {"2026-11-27", "2026-11-26T14:05Z", "2026-11-25/2026-11-26", ""}) {
    json e = entry("vo.a.b", 1.0);
    e["date"] = date;
    EXPECT_EQ(error_of_entry(e), "") << date;
  }
  for (const char* date : {"27 Nov 2026", "2026-13-01", "2026-11-32", "2026-11-26T25:00Z", "2026-11-26/", "2026-1-1"}) {
    json e = entry("vo.a.b", 1.0);
    e["date"] = date;
    EXPECT_NE(error_of_entry(e), "") << date;
  }
}

TEST(FiguresFile, AControlCharacterIsAnErrorShownEscaped) {
  json e = entry("vo.a.b", 1.0);
  e["figure"] = std::string("two\nlines\x1b[31m");
  const std::string message = error_of_entry(e);
  EXPECT_NE(message.find("control character"), std::string::npos) << message;
  EXPECT_NE(message.find("two\\nlines\\x1B[31m"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(message.find('\x1b'), std::string::npos);
}

TEST(FiguresFile, ReferencesNameAFigureWhoseValueNamesNone) {
  const json target = entry("vo.a.ate", 0.94);
  EXPECT_EQ(error_of(file_of(json::array({target, entry("top.parts.vo", "ATE {vo.a.ate}")}))), "");
  EXPECT_NE(error_of(file_of(json::array({target, entry("top.parts.vo", "ATE {vo.a.missing}")}))).find("names no figure"),
            std::string::npos);
  json note = entry("slam.a.ate", 0.93);
  note["note"] = "(VO {vo.a.none})";
  EXPECT_NE(error_of(file_of(json::array({target, note}))).find("names no figure"), std::string::npos);
  // One step only: a value naming a value that names another could loop.
  const std::string chain = error_of(file_of(
      json::array({target, entry("top.parts.a", "see {vo.a.ate}"), entry("top.parts.b", "see {top.parts.a}")})));
  EXPECT_NE(chain.find("whose value names others"), std::string::npos) << chain;
  // Braces around what is not an id are text.
  EXPECT_EQ(error_of(file_of(json::array({entry("top.parts.tools", "`tools/{eval,replay}` {} {X.Y}")}))), "");
}

TEST(FiguresFile, ReferencesAreFoundWhereIdsAreBraced) {
  const auto refs = references("a {vo.x} b {c,d} {slam.y.z}{}");
  ASSERT_EQ(refs.size(), 2u);
  EXPECT_EQ(refs[0].id, "vo.x");
  EXPECT_EQ(refs[0].begin, 2u);
  EXPECT_EQ(refs[0].end, 8u);
  EXPECT_EQ(refs[1].id, "slam.y.z");
}

TEST(FiguresFile, AMissingFileIsAnInputErrorNamingIt) {
  try {
    load("/nonexistent/figures.json");
    FAIL() << "loaded a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/figures.json"), std::string::npos);
  }
}

TEST(FiguresFile, EveryComponentHasAReadme) {
  EXPECT_EQ(readme_path("top"), "README.md");
  EXPECT_EQ(readme_path("sim"), "drivers/sim/README.md");
  EXPECT_EQ(readme_path("eval"), "tools/eval/README.md");
  EXPECT_THROW(readme_path("nowhere"), std::out_of_range);
  for (const std::string& component : readme_components())
    EXPECT_TRUE(std::filesystem::exists(test::source_dir() / readme_path(component))) << readme_path(component);
}

// test/support's view of the same file, as the data tests use it.
TEST(TestFigures, AFigureComesInSiWithItsLimit) {
  const test::Figure& ate = test::figure("vo.fr1_xyz.ate_rmse");
  ASSERT_TRUE(ate.has_limit);
  EXPECT_GT(ate.value, 0.0);
  EXPECT_LT(ate.value, 0.05) << "an ATE in metres";
  EXPECT_LE(ate.value, ate.max);
  EXPECT_TRUE(test::within_limit(ate.value, ate));
  EXPECT_FALSE(test::within_limit(ate.max * 1.01, ate));
  EXPECT_TRUE(test::no_worse_than(ate.value * 1.09, ate));
  EXPECT_FALSE(test::no_worse_than(ate.value * 1.11, ate));
  EXPECT_THROW(test::figure("vo.no_such.figure"), std::runtime_error);
  EXPECT_THROW(test::figure("kinect.identity.rgb"), std::runtime_error) << "a text figure has no number";
}

}  // namespace
}  // namespace kestrel::figures
