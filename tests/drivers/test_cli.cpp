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
  EXPECT_DOUBLE_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--size-factor", "0.01"}).size_factor,
                   0.01);
  // The default is the furthest stage that exists.
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.vtu"}).until, "quasi-structured");
  // No time budget unless asked: the mesh then does not depend on timing.
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.vtu"}).face_time_budget, 0.0);
  EXPECT_DOUBLE_EQ(
      p({"mesh", "m.step", "-o", "o.vtu", "--face-time-budget", "0.5"}).face_time_budget, 0.5);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--face-time-budget", "-1"})
                .find("--face-time-budget"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--face-time-budget"), std::string::npos);
}

TEST(Cli, DistributedThreshold) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).distributed_threshold.has_value());
  EXPECT_EQ(
      *p({"mesh", "m.step", "-o", "o.vtu", "--distributed-threshold", "300"}).distributed_threshold,
      300);
  EXPECT_EQ(*p({"crossfield", "m.step", "--check", "--distributed-threshold", "1e6"})
                 .distributed_threshold,
            1000000);
  for (const char* bad : {"0", "-5", "2.5", "x", "3e9"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--distributed-threshold", bad})
                  .find("--distributed-threshold"),
              std::string::npos)
        << bad;
  EXPECT_NE(help("mesh").find("--distributed-threshold"), std::string::npos);
}

TEST(Cli, FieldChangeAndIterations) {
  const Arguments plain = p({"mesh", "m.step", "-o", "o.vtu"});
  EXPECT_TRUE(plain.field_change.empty());
  EXPECT_FALSE(plain.field_iterations.has_value());
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.vtu", "--field-change", "rms"}).field_change, "rms");
  EXPECT_EQ(p({"crossfield", "m.step", "--check", "--field-change", "max"}).field_change, "max");
  EXPECT_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--field-iterations", "20"}).field_iterations, 20);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--field-change", "l2"}).find("--field-change"),
      std::string::npos);
  for (const char* bad : {"0", "-1", "2.5", "x", "1001"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--field-iterations", bad})
                  .find("--field-iterations"),
              std::string::npos)
        << bad;
  EXPECT_NE(help("mesh").find("--field-change"), std::string::npos);
  EXPECT_NE(help("mesh").find("--field-iterations"), std::string::npos);
}

TEST(Cli, FieldStall) {
  const Arguments plain = p({"mesh", "m.step", "-o", "o.vtu"});
  EXPECT_FALSE(plain.field_stall.has_value());
  EXPECT_FALSE(plain.field_stall_ratio.has_value());
  const Arguments k = p({"mesh", "m.step", "-o", "o.vtu", "--field-stall", "5"});
  EXPECT_EQ(*k.field_stall, 5);
  EXPECT_FALSE(k.field_stall_ratio.has_value());
  const Arguments kr = p({"crossfield", "m.step", "--check", "--field-stall", "8:0.75"});
  EXPECT_EQ(*kr.field_stall, 8);
  EXPECT_DOUBLE_EQ(*kr.field_stall_ratio, 0.75);
  EXPECT_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--field-stall", "0"}).field_stall, 0);
  for (const char* bad : {"-1", "2.5", "x", "1001", "5:", "5:0", "5:1", "5:x", ":0.5"})
    EXPECT_NE(
        error_of({"mesh", "m.step", "-o", "o.vtu", "--field-stall", bad}).find("--field-stall"),
        std::string::npos)
        << bad;
  EXPECT_NE(help("mesh").find("--field-stall"), std::string::npos);
}

TEST(Cli, FieldStallRevolution) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).field_stall_revolution.has_value());
  EXPECT_EQ(
      *p({"mesh", "m.step", "-o", "o.vtu", "--field-stall-revolution", "0"}).field_stall_revolution,
      0);
  EXPECT_EQ(*p({"crossfield", "m.step", "--check", "--field-stall-revolution", "6"})
                 .field_stall_revolution,
            6);
  for (const char* bad : {"-1", "2.5", "x", "1001", "4:0.5"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--field-stall-revolution", bad})
                  .find("--field-stall-revolution"),
              std::string::npos)
        << bad;
  EXPECT_NE(help("mesh").find("--field-stall-revolution"), std::string::npos);
  EXPECT_NE(help("crossfield").find("--field-stall-revolution"), std::string::npos);
}

TEST(Cli, FieldSettled) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).field_settled.has_value());
  EXPECT_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--field-settled", "0"}).field_settled, 0);
  EXPECT_EQ(*p({"sizemap", "m.step", "-o", "s.vtu", "--field-settled", "3"}).field_settled, 3);
  for (const char* bad : {"-1", "2.5", "x", "1001"})
    EXPECT_NE(
        error_of({"mesh", "m.step", "-o", "o.vtu", "--field-settled", bad}).find("--field-settled"),
        std::string::npos)
        << bad;
  EXPECT_NE(help("mesh").find("--field-settled"), std::string::npos);
  EXPECT_NE(help("crossfield").find("--field-settled"), std::string::npos);
}

TEST(Cli, FieldRegular) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).field_regular.has_value());
  EXPECT_FALSE(*p({"mesh", "m.step", "-o", "o.vtu", "--field-regular", "off"}).field_regular);
  EXPECT_TRUE(*p({"crossfield", "m.step", "-o", "c.vtu", "--field-regular", "on"}).field_regular);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--field-regular", "1"}).find("--field-regular"),
      std::string::npos);
  EXPECT_NE(help("mesh").find("--field-regular"), std::string::npos);
  EXPECT_NE(help("crossfield").find("--field-regular"), std::string::npos);
  EXPECT_NE(help("sizemap").find("--field-regular"), std::string::npos);
}

TEST(Cli, PassAfterCuts) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).pass_after_cuts.has_value());
  EXPECT_FALSE(*p({"mesh", "m.step", "-o", "o.vtu", "--pass-after-cuts", "off"}).pass_after_cuts);
  EXPECT_TRUE(*p({"mesh", "m.step", "-o", "o.vtu", "--pass-after-cuts", "on"}).pass_after_cuts);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--pass-after-cuts", "1"})
                .find("--pass-after-cuts"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--pass-after-cuts"), std::string::npos);
}

TEST(Cli, FieldShortcuts) {
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.vtu"}).field_shortcuts.empty());
  for (const char* v : {"all", "uniform", "none"})
    EXPECT_EQ(p({"mesh", "m.step", "-o", "o.vtu", "--field-shortcuts", v}).field_shortcuts, v);
  EXPECT_EQ(p({"crossfield", "m.step", "--check", "--field-shortcuts", "none"}).field_shortcuts,
            "none");
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--field-shortcuts", "some"})
                .find("--field-shortcuts"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--field-shortcuts"), std::string::npos);
}

TEST(Cli, CrossFieldAndSeparatrixMethod) {
  const Arguments a =
      p({"mesh", "m.step", "-o", "o.vtu", "--cross-field", "f.txt", "--method", "separatrix"});
  EXPECT_EQ(a.cross_field, "f.txt");
  EXPECT_TRUE(a.separatrix_method);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).separatrix_method);
  EXPECT_EQ(error_of({"mesh", "m.step", "-o", "o.vtu", "--method", "other"}),
            "--method: expected default, holomorphic, auto or separatrix, got 'other'");
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu", "--method", "auto"}).separatrix_method);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--cross-field", "f.txt", "--until", "background"})
          .find("--cross-field needs a quad mesh"),
      std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--cross-field"}).find("missing value"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--cross-field FIELD"), std::string::npos);
}

// --smooth-groups is an opt-in of paper 004's methods, refused up front elsewhere.
TEST(Cli, SmoothGroupsOnlyWithTheHolomorphicMethods) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.msh", "--method", "holomorphic"}).smooth_groups);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.msh", "--method", "holomorphic", "--smooth-groups"})
                  .smooth_groups);
  EXPECT_TRUE(
      p({"mesh", "m.step", "-o", "o.msh", "--smooth-groups", "--method", "auto"}).smooth_groups);
  EXPECT_EQ(error_of({"mesh", "m.step", "-o", "o.msh", "--smooth-groups"}),
            "--smooth-groups: only with --method holomorphic or auto");
  EXPECT_EQ(
      error_of({"mesh", "m.step", "-o", "o.msh", "--smooth-groups", "--method", "separatrix"}),
      "--smooth-groups: only with --method holomorphic or auto");
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--method", "auto", "--smooth-groups",
                      "--block-structured"})
                .find("not together"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--method", "auto", "--smooth-groups",
                      "--until", "background"})
                .find("needs a quad mesh"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--smooth-groups"), std::string::npos);
}

TEST(Cli, SecondOrder) {
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.cgns"}).order, 1);
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--order", "2"}).order, 2);
  for (const char* n : {"3", "4", "5"})
    EXPECT_EQ(p({"mesh", "m.step", "-o", "o.vtu", "--order", n}).order, std::stoi(n));
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.cgns", "--order", "4"}).order, 4);
  for (const char* n : {"0", "6", "2.5", "22"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--order", n}).find("--order"),
              std::string::npos);
  // CGNS has no elements of order 5.
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--order", "5"}).find("order 5"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--order", "2", "--until", "background"})
                .find("quad mesh"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--order", "2", "--block-structured"})
                .find("--block-patches"),
            std::string::npos);
}

TEST(Cli, BlockPatchesTakeAnOrderAndTheCoarseLayout) {
  const Arguments a = p({"mesh", "m.step", "-o", "o.vtu", "--block-patches", "--order", "3"});
  EXPECT_TRUE(a.block_patches);
  EXPECT_FALSE(a.block_structured);
  EXPECT_TRUE(a.coarse_layout);
  EXPECT_FALSE(
      p({"mesh", "m.step", "-o", "o.msh", "--block-patches", "--order", "2", "--layout", "dense"})
          .coarse_layout);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--block-patches"}).find("--order"),
            std::string::npos);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.xyz", "--block-patches", "--order", "2"}).find("PLOT3D"),
      std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--block-patches", "--order", "2",
                      "--block-structured"})
                .find("not with --block-structured"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--block-patches", "--order", "5"})
                .find("order 5"),
            std::string::npos);
}

TEST(Cli, LayoutDenseIsTheDefaultOfBlockStructured) {
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.cgns", "--block-structured"}).coarse_layout);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.xyz"}).coarse_layout);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse"}).coarse_layout);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.cgns", "--block-structured", "--layout", "dense"})
                   .coarse_layout);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.cgns", "--block-structured", "--layout", "coarse"})
                  .coarse_layout);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--block-structured", "--layout", "fine"})
                .find("not coarse or dense"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--layout", "dense"})
                .find("only with --block-structured"),
            std::string::npos);
}

TEST(Cli, ConeAngleInDegreesBetweenZeroAndNinety) {
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse"}).cone_angle_deg, 0.0);
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--cone-angle", "60"})
                .cone_angle_deg,
            60.0);
  for (const char* bad : {"0", "90", "-5", "sixty"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--cone-angle", bad})
                  .find("--cone-angle"),
              std::string::npos)
        << bad;
}

TEST(Cli, FinePlacementChoosesTheCoarseMeshsPlacementChanges) {
  const auto both = p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse"});
  EXPECT_TRUE(both.fine_laplacian && both.fine_input_spacing && !both.fine_patch);
  const auto patch =
      p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--fine-placement", "patch"});
  EXPECT_TRUE(patch.fine_laplacian && patch.fine_input_spacing && patch.fine_patch);
  const auto former =
      p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--fine-placement", "former"});
  EXPECT_FALSE(former.fine_laplacian || former.fine_input_spacing || former.fine_patch);
  const auto spacing =
      p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--fine-placement", "spacing"});
  EXPECT_TRUE(!spacing.fine_laplacian && spacing.fine_input_spacing);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--fine-placement",
                      "uniform"})
                .find("--fine-placement"),
            std::string::npos);
}

TEST(Cli, RepairsChooseHowTheCoarseLayoutRepairsFolds) {
  const auto grow = p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse"});
  EXPECT_EQ(grow.repairs, layout::Repairs::Grow);
  const auto local =
      p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--repairs", "local"});
  EXPECT_EQ(local.repairs, layout::Repairs::Local);
  const auto restore =
      p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--repairs", "restore"});
  EXPECT_EQ(restore.repairs, layout::Repairs::Restore);
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--repairs", "grow"}).repairs,
            layout::Repairs::Grow);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.xyz", "--layout", "coarse", "--repairs", "bound"})
                .find("is not grow, local or restore"),
            std::string::npos);
}

TEST(Cli, FillComparisonChoosesWhichKeptFillsAreCompared) {
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh"}).fill_comparison, "");  // the default
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--fill-comparison", "mean"}).fill_comparison,
            "mean");
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--fill-comparison", "irregular"}).fill_comparison,
            "irregular");
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--fill-comparison", "all"}).fill_comparison,
            "all");
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--fill-comparison", "none"})
                .find("is not irregular, all or mean"),
            std::string::npos);
}

TEST(Cli, BlockStructuredNeedsCgnsAndQuads) {
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.cgns", "--block-structured"}).block_structured);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.cgns"}).block_structured);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.CGNS", "--block-structured"}).block_structured);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--block-structured"}).find("-o FILE.cgns"),
            std::string::npos);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.cgns", "--block-structured", "--until", "background"})
          .find("quad mesh"),
      std::string::npos);
  EXPECT_NE(
      error_of({"sizemap", "m.step", "-o", "s.vtu", "--block-structured"}).find("unknown option"),
      std::string::npos);
}

TEST(Cli, Plot3dIsTheBlockLayout) {
  // A PLOT3D output is the quad layout's blocks, with or without --block-structured.
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.xyz"}).block_structured);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.P3D", "--block-structured"}).block_structured);
  const Arguments a = p({"mesh", "m.step", "-o", "o.xyz", "--plot3d-stream", "--plot3d-single"});
  EXPECT_TRUE(a.plot3d_stream);
  EXPECT_TRUE(a.plot3d_single);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.xyz"}).plot3d_stream);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.xyz", "--until", "background"}).find("PLOT3D"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.xyz", "--order", "3"}).find("high-order quads"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.cgns", "--plot3d-stream"}).find("PLOT3D output"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--plot3d-single"}).find("PLOT3D output"),
            std::string::npos);
  EXPECT_NE(
      error_of({"sizemap", "m.step", "-o", "s.vtu", "--plot3d-stream"}).find("unknown option"),
      std::string::npos);
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
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "-1"}).find("--size: must be positive"),
      std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "0"}).find("--size"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "abc"}).find("not a number"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "1.5x"}).find("not a number"),
            std::string::npos);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--size-factor", "nan"}).find("--size-factor"),
      std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size", "1", "--size-factor", "0.1"})
                .find("not both"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--threads", "0"}).find("--threads"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size"}).find("missing value"),
            std::string::npos);
}

TEST(Cli, ClampedSizingIsTheDefaultAndItsTwoOptions) {
  // The default rules, clamped, stand for --curvature-edges 0 --size-min-ratio 0.17; gmsh is
  // another name for them (recorded as clamped); options given explicitly win, whatever their
  // place on the line.
  const Arguments d = p({"mesh", "m.step", "-o", "o.vtu"});
  EXPECT_EQ(d.sizing, "clamped");
  ASSERT_TRUE(d.curvature_edges && d.size_min_ratio);
  EXPECT_DOUBLE_EQ(*d.curvature_edges, 0.0);
  EXPECT_DOUBLE_EQ(*d.size_min_ratio, kClampedSizeMinRatio);
  EXPECT_FALSE(d.size_min);
  const Arguments g = p({"sizemap", "m.step", "-o", "s.vtu", "--sizing", "gmsh"});
  EXPECT_EQ(g.sizing, "clamped");
  ASSERT_TRUE(g.curvature_edges && g.size_min_ratio);
  EXPECT_DOUBLE_EQ(*g.curvature_edges, 0.0);
  EXPECT_DOUBLE_EQ(*g.size_min_ratio, kClampedSizeMinRatio);
  const Arguments e = p({"sizemap", "m.step", "-o", "s.vtu", "--curvature-edges", "8", "--sizing",
                         "clamped", "--size-min", "0.4"});
  EXPECT_DOUBLE_EQ(*e.curvature_edges, 8.0);
  EXPECT_DOUBLE_EQ(*e.size_min, 0.4);
  EXPECT_FALSE(e.size_min_ratio);
  // paper: rule (i) of Sec. 4.1 below every floor, SizeMapOptions' defaults.
  const Arguments pa = p({"mesh", "m.step", "-o", "o.vtu", "--sizing", "paper"});
  EXPECT_EQ(pa.sizing, "paper");
  EXPECT_FALSE(pa.curvature_edges || pa.size_min_ratio || pa.size_min);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--sizing", "fast"}).find("clamped, gmsh"),
            std::string::npos);
  // The default rules do not refuse --until background; named on the line, like every sizing
  // option, they do, since they would change nothing there.
  EXPECT_EQ(error_of({"mesh", "m.step", "-o", "o.vtu", "--until", "background"}), "");
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--sizing", "gmsh", "--until", "background"}), "");
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--sizing", "paper", "--until", "background"}),
      "");
  // Commands without a size map get none of its options.
  const Arguments c = p({"crossfield", "m.step", "-o", "c.vtu"});
  EXPECT_FALSE(c.curvature_edges || c.size_min_ratio);
}

TEST(Cli, SizeMapOptions) {
  const Arguments a =
      p({"sizemap", "m.step", "-o", "s.vtu", "--sizemap", "features", "--curve-edges", "3:8,7:12",
         "--face-quads", "2:100", "--corner-size", "0:0.5", "--curve-size", "4:1.5", "--face-size",
         "1:2", "--quads", "5000"});
  EXPECT_EQ(a.command, Command::SizeMap);
  EXPECT_EQ(a.sizemap, "features");
  EXPECT_EQ(a.curve_edges, (std::vector<std::pair<int, int>>{{3, 8}, {7, 12}}));
  EXPECT_EQ(a.face_quads, (std::vector<std::pair<int, double>>{{2, 100.0}}));
  EXPECT_EQ(a.corner_sizes, (std::vector<std::pair<int, double>>{{0, 0.5}}));
  EXPECT_DOUBLE_EQ(a.quads, 5000);
  EXPECT_NE(error_of({"sizemap", "m.step", "-o", "s.vtu", "--sizemap", "magic"}).find("--sizemap"),
            std::string::npos);
  EXPECT_NE(error_of({"sizemap", "m.step", "-o", "s.vtu", "--curve-edges", "3"}).find("ID:VALUE"),
            std::string::npos);
  EXPECT_NE(
      error_of({"sizemap", "m.step", "-o", "s.vtu", "--curve-edges", "x:4"}).find("entity id"),
      std::string::npos);
  EXPECT_NE(
      error_of({"sizemap", "m.step", "-o", "s.vtu", "--curve-edges", "3:4.5"}).find("integer"),
      std::string::npos);
  EXPECT_NE(error_of({"sizemap", "m.step", "-o", "s.vtu", "--curve-size", "3:-1"}).find("positive"),
            std::string::npos);
  EXPECT_NE(error_of({"sizemap", "m.step"}).find("missing -o"), std::string::npos);
  // The mesh command takes them too (its quad stages use the size map), but not with --until
  // background, where they would change nothing: refused rather than silently ignored.
  const Arguments m = p({"mesh", "m.step", "-o", "o.vtu", "--curve-edges", "3:8",
                         "--curvature-edges", "0", "--curve-size", "4:1.5", "--quads", "5000"});
  EXPECT_EQ(m.curve_edges, (std::vector<std::pair<int, int>>{{3, 8}}));
  ASSERT_TRUE(m.curvature_edges.has_value());
  EXPECT_DOUBLE_EQ(*m.curvature_edges, 0.0);
  EXPECT_DOUBLE_EQ(
      *p({"sizemap", "m.step", "-o", "s.vtu", "--curvature-edges", "8"}).curvature_edges, 8.0);
  EXPECT_FALSE(
      p({"mesh", "m.step", "-o", "o.vtu", "--sizing", "paper"}).curvature_edges.has_value());
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).face_curvature);
  EXPECT_TRUE(p({"sizemap", "m.step", "-o", "s.vtu", "--face-curvature"}).face_curvature);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.msh", "--odd-slivers"}).odd_slivers);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.msh"}).odd_slivers);
  EXPECT_TRUE(p({"mesh", "m.step", "-o", "o.msh", "--one-edge-slivers"}).one_edge_slivers);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.msh"}).one_edge_slivers);
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).feature_ratio.has_value());
  EXPECT_DOUBLE_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--feature-ratio", "0"}).feature_ratio,
                   0.0);
  EXPECT_DOUBLE_EQ(*p({"sizemap", "m.step", "-o", "s.vtu", "--feature-ratio", "0.5"}).feature_ratio,
                   0.5);
  for (const char* bad : {"-0.1", "1.5", "x", "nan"})
    EXPECT_NE(
        error_of({"mesh", "m.step", "-o", "o.vtu", "--feature-ratio", bad}).find("--feature-ratio"),
        std::string::npos)
        << bad;
  EXPECT_FALSE(p({"mesh", "m.step", "-o", "o.vtu"}).thin_aspect.has_value());
  EXPECT_DOUBLE_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--thin-aspect", "0"}).thin_aspect, 0.0);
  EXPECT_DOUBLE_EQ(*p({"sizemap", "m.step", "-o", "s.vtu", "--thin-aspect", "5"}).thin_aspect, 5.0);
  for (const char* bad : {"-1", "x", "inf", "nan"})
    EXPECT_NE(
        error_of({"mesh", "m.step", "-o", "o.vtu", "--thin-aspect", bad}).find("--thin-aspect"),
        std::string::npos)
        << bad;
  // A size-map option: refused with --until background, as the others.
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--until", "background", "--thin-aspect", "4"})
          .find("size-map options"),
      std::string::npos);

  EXPECT_DOUBLE_EQ(*p({"sizemap", "m.step", "-o", "s.vtu", "--size-min", "0.25"}).size_min, 0.25);
  for (const char* bad : {"0", "-1", "x"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size-min", bad}).find("--size-min"),
              std::string::npos)
        << bad;
  EXPECT_FALSE(
      p({"mesh", "m.step", "-o", "o.vtu", "--sizing", "paper"}).size_min_ratio.has_value());
  EXPECT_DOUBLE_EQ(*p({"mesh", "m.step", "-o", "o.vtu", "--size-min-ratio", "0.17"}).size_min_ratio,
                   0.17);
  for (const char* bad : {"0", "-0.1", "1.5", "x"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--size-min-ratio", bad})
                  .find("--size-min-ratio"),
              std::string::npos)
        << bad;
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--size-min", "1", "--size-min-ratio", "0.2"})
          .find("give one, not both"),
      std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--until", "background", "--size-min", "1"})
                .find("--until background"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--until", "background", "--face-curvature"})
                .find("--until background"),
            std::string::npos);
  EXPECT_NE(
      error_of({"mesh", "m.step", "-o", "o.vtu", "--until", "background", "--curve-size", "4:1"})
          .find("--until background"),
      std::string::npos);
  for (const char* bad : {"2", "-1", "x", "8x", "inf"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--curvature-edges", bad})
                  .find("--curvature-edges"),
              std::string::npos)
        << bad;
  EXPECT_NE(error_of({"crossfield", "m.step", "-o", "c.vtu", "--curve-size", "4:1"})
                .find("unknown option"),
            std::string::npos);
}

TEST(Cli, MissingPiecesAndUnknowns) {
  EXPECT_NE(error_of({"mesh", "m.step"}).find("missing -o"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "-o", "x.vtu"}).find("missing MODEL"), std::string::npos);
  EXPECT_NE(error_of({"frobnicate"}).find("unknown command"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.vtu", "--bogus"}).find("unknown option '--bogus'"),
            std::string::npos);
  EXPECT_NE(error_of({"example", "rocket", "-o", "r.step"}).find("unknown example"),
            std::string::npos);
  EXPECT_NE(error_of({"info", "a.step", "b.step"}).find("unexpected argument"), std::string::npos);
}

// An id given twice in one option, even over two occurrences of it, is refused at parse time:
// which value was meant cannot be guessed (it used to be found after the curves were meshed).
TEST(Cli, AnIdGivenTwiceIsRefused) {
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--curve-edges", "3:8,3:10"})
                .find("curve 3 is given twice"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--face-size", "1:2", "--face-size", "1:3"})
                .find("face 1 is given twice"),
            std::string::npos);
  EXPECT_NE(
      error_of({"sizemap", "m.step", "-o", "o.vtu", "--corner-size", "4:1,4:1"}).find("corner 4"),
      std::string::npos);
  // Repeating the option adds to it.
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--curve-size", "1:2", "--curve-size", "5:3"})
                .curve_sizes.size(),
            2u);
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--curve-edges", "1:8,5:10"}).curve_edges.size(),
            2u);
}

// Each ID:VALUE option's hint shows a value the option itself accepts.
TEST(Cli, HintsShowAcceptedValues) {
  for (const std::string option :
       {"--curve-edges", "--face-quads", "--curve-size", "--face-size", "--corner-size"}) {
    const std::string err = error_of({"mesh", "m.step", "-o", "o.msh", option, "7"});
    const auto at = err.find("(e.g. " + option + " ");
    ASSERT_NE(at, std::string::npos) << err;
    const std::size_t from = at + std::string("(e.g. ").size() + option.size() + 1;
    const std::string example = err.substr(from, err.find(')', at) - from);
    EXPECT_FALSE(example.empty()) << err;
    EXPECT_EQ(error_of({"mesh", "m.step", "-o", "o.msh", option, example}), "")
        << option << " " << example;
  }
}

TEST(Cli, MaxQuads) {
  EXPECT_LT(p({"mesh", "m.step", "-o", "o.msh"}).max_quads, 0);  // the default applies
  EXPECT_DOUBLE_EQ(p({"mesh", "m.step", "-o", "o.msh", "--max-quads", "1e6"}).max_quads, 1e6);
  EXPECT_DOUBLE_EQ(p({"sizemap", "m.step", "-o", "o.vtu", "--max-quads", "0"}).max_quads, 0);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--max-quads", "-1"}).find("--max-quads"),
            std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--max-quads", "lots"}).find("--max-quads"),
            std::string::npos);
  EXPECT_NE(help("mesh").find("--max-quads N"), std::string::npos);
  EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--curve-edges", "1:4000000000"})
                .find("more than any mesh"),
            std::string::npos);
}

TEST(Cli, SecondPassQuads) {
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh"}).second_pass_quads, -1);  // the default applies
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--second-pass-quads", "0"}).second_pass_quads, 0);
  EXPECT_EQ(p({"mesh", "m.step", "-o", "o.msh", "--second-pass-quads", "800"}).second_pass_quads,
            800);
  for (const std::string bad : {"-1", "2.5", "many"})
    EXPECT_NE(error_of({"mesh", "m.step", "-o", "o.msh", "--second-pass-quads", bad})
                  .find("--second-pass-quads"),
              std::string::npos)
        << bad;
  EXPECT_NE(error_of({"sizemap", "m.step", "-o", "o.vtu", "--second-pass-quads", "10"}), "");
  EXPECT_NE(help("mesh").find("--second-pass-quads N"), std::string::npos);
}

// The example is written in the format its extension names; other names are refused up front.
TEST(Cli, ExampleFormatByExtension) {
  EXPECT_EQ(p({"example", "wing-body", "-o", "w.step"}).output, "w.step");
  EXPECT_EQ(p({"example", "wing-body", "-o", "w.BRP"}).output, "w.BRP");
  EXPECT_EQ(p({"example", "wing-body", "-o", "w.brep"}).output, "w.brep");
  for (const std::string bad : {"w.cgns", "w.iges", "w"})
    EXPECT_NE(error_of({"example", "wing-body", "-o", bad}).find(".brep"), std::string::npos)
        << bad;
}

// --help anywhere gives the help alone: options before it, which were never checked together,
// are dropped (the fuzzer found --size-min and --size-min-ratio both set on a help request).
TEST(Cli, HelpDropsTheOptionsBeforeIt) {
  const Arguments a = p({"mesh", "m.step", "--size-min", "1", "--size-min-ratio", "0.5", "--help"});
  EXPECT_EQ(a.command, Command::Help);
  EXPECT_EQ(a.help_topic, "mesh");
  EXPECT_FALSE(a.size_min.has_value());
  EXPECT_FALSE(a.size_min_ratio.has_value());
}

}  // namespace
}  // namespace qsmesh::cli
