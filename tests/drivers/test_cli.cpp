#include <gtest/gtest.h>

#include "cli.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::cli {
namespace {

Arguments p(std::vector<std::string> a) { return parse(a); }

std::string error_of(std::vector<std::string> a) {
  try {
    (void)parse(a);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Cli, MeshOptions) {
  const Arguments a = p({"mesh", "m.step", "-o", "out.cgns", "--size", "2.5", "--threads", "3",
                         "--stats", "s.json", "--until", "background"});
  EXPECT_EQ(a.command, Command::Mesh);
  EXPECT_EQ(a.model, "m.step");
  EXPECT_EQ(a.output, "out.cgns");
  ASSERT_TRUE(a.size.has_value());
  EXPECT_DOUBLE_EQ(*a.size, 2.5);
  EXPECT_EQ(a.threads, 3);
  EXPECT_EQ(a.stats, "s.json");
  EXPECT_EQ(a.until, "background");
  EXPECT_DOUBLE_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--size-factor", "0.01"}).size_factor, 0.01);
}

TEST(Cli, HelpEverywhere) {
  EXPECT_EQ(p({}).command, Command::Help);
  EXPECT_EQ(p({"--help"}).command, Command::Help);
  const Arguments a = p({"mesh", "--help"});
  EXPECT_EQ(a.command, Command::Help);
  EXPECT_EQ(a.help_topic, "mesh");
  EXPECT_NE(help("mesh").find("--size-factor"), std::string::npos);
  EXPECT_NE(help("info").find("--json"), std::string::npos);
  EXPECT_NE(help("").find("example"), std::string::npos);
}

TEST(Cli, BadSizesNameTheOption) {
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "-1"}).find("--size: must be positive"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "0"}).find("--size"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "abc"}).find("not a number"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "1.5x"}).find("not a number"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size-factor", "nan"}).find("--size-factor"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "1", "--size-factor", "0.1"}).find("not both"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--threads", "0"}).find("--threads"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size"}).find("missing value"), std::string::npos);
}

TEST(Cli, MissingPiecesAndUnknowns) {
  EXPECT_NE(error_of({"mesh", "m.step"}).find("missing -o"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "-o", "x.vtu"}).find("missing MODEL"), std::string::npos);
  EXPECT_NE(error_of({"frobnicate"}).find("unknown command"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--bogus"}).find("unknown option '--bogus'"), std::string::npos);
  EXPECT_NE(error_of({"example", "rocket", "-o", "r.step"}).find("unknown example"), std::string::npos);
  EXPECT_NE(error_of({"info", "a.step", "b.step"}).find("unexpected argument"), std::string::npos);
}

}  // namespace
}  // namespace qsmesh::cli
