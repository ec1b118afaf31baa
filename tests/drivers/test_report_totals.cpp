// Totals of per-face reports by their declared field names (drivers/report_totals.hpp): what the
// summary and --stats write of the quasi-structured stage.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "qsmesh/core/error.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "report_totals.hpp"

namespace qsmesh::cli {
namespace {

TEST(ReportTotals, SumsCountsAndArraysAndCountsFlagsByName) {
  std::vector<parallel::QuasiReport> faces(3);
  faces[0].by_pattern = true;
  faces[0].pattern = "grid";
  faces[1].by_pattern = true;
  faces[1].by_comparison = true;
  faces[2].refusal = "unstructured_better";
  faces[2].gave_way = true;
  faces[2].improvement.irregular_before = 7;
  faces[2].improvement.irregular_after = 3;
  faces[2].improvement.cavities = {1, 0, 2, 0};
  faces[2].improvement.disk_replaced = 4;
  faces[2].improvement.time_budget_hit = true;
  faces[1].improvement.cavities = {0, 5, 0, 1};
  faces[1].improvement.disk_replaced = 1;
  const ReportTotals t = ReportTotals::sum(std::span<const parallel::QuasiReport>(faces));
  EXPECT_EQ(t("faces_meshed_by_pattern"), 2);
  EXPECT_EQ(t("faces_meshed_by_pattern_after_comparison"), 1);
  EXPECT_EQ(t("faces_fill_gave_way_to_unstructured"), 1);
  EXPECT_EQ(t("irregular_unstructured_before"), 7);
  EXPECT_EQ(t("irregular_unstructured_after_cavities"), 3);
  EXPECT_EQ(t("cavities_remeshed_per_step", 1), 5);
  EXPECT_EQ(t("cavities_remeshed_per_step", 2), 2);
  EXPECT_EQ(t("disk_cavities_replaced"), 5);
  EXPECT_EQ(t("faces_time_budget_hit"), 1);
  EXPECT_THROW((void)t("pattern"), Error);  // text is per face, not summed
  EXPECT_THROW((void)t("no_such_field"), Error);
  EXPECT_THROW((void)t("cavities_remeshed_per_step", 4), Error);
}

TEST(ReportTotals, WritesEveryTotalInTheOrderOfTheFields) {
  const std::vector<parallel::QuasiReport> none;
  const ReportTotals t = ReportTotals::sum(std::span<const parallel::QuasiReport>(none));
  JsonWriter j;
  j.begin_object();
  t.write(j);
  j.end_object();
  const std::string json = j.str();
  // The keys of --stats, in this order (scripts read them by name; people read them in order).
  std::size_t at = 0;
  for (const char* key :
       {"faces_meshed_by_pattern", "faces_meshed_by_pattern_after_comparison",
        "faces_fill_gave_way_to_unstructured", "irregular_unstructured_before",
        "irregular_unstructured_after_cavities", "cavities_remeshed_per_step",
        "disk_defects_before", "disk_defects_after", "disk_cavities_replaced",
        "faces_time_budget_hit", "faces_second_pass_kept", "faces_meshed_by_holomorphic",
        "faces_meshed_by_field", "field_regions"}) {
    const std::size_t found = json.find(std::string("\"") + key + "\"", at);
    ASSERT_NE(found, std::string::npos) << key << " in " << json;
    at = found;
  }
  EXPECT_EQ(t.fields().size(), 14U);
  EXPECT_EQ(json.find("\"pattern\""), std::string::npos);
  EXPECT_EQ(json.find("\"holomorphic\""), std::string::npos);  // text is per face
  EXPECT_EQ(json.find("\"field_refusal\""), std::string::npos);
}

}  // namespace
}  // namespace qsmesh::cli
