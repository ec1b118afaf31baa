// The request estimates and refusals of limits.hpp, without a model file or MPI.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "limits.hpp"

namespace qsmesh::cli {
namespace {

// Two unit squares side by side sharing curve 1: face 0 bounded by curves 0, 1, 2, 3 and face 1
// by 1, 4, 5, 6; every curve 1 long.
ModelMeasures two_squares() {
  ModelMeasures m;
  m.face_area = {1.0, 1.0};
  m.curve_length = std::vector<double>(7, 1.0);
  m.face_curves = {{0, 1, 2, 3}, {1, 4, 5, 6}};
  return m;
}

TEST(Limits, SizeCapGivesAreaOverSizeSquared) {
  SizeRequest r;
  r.size_max = 0.1;
  const RequestEstimate e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 200.0, 1e-9);
  EXPECT_EQ(e.dominant, "the size cap");
}

TEST(Limits, QuadsTargetIsSharedByArea) {
  SizeRequest r;
  r.size_max = 0.1;
  r.target_quads = 5000;
  const RequestEstimate e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 5000.0, 1e-9);
  EXPECT_EQ(e.dominant, "--quads 5000");
}

TEST(Limits, PrescriptionsRaiseTheBound) {
  SizeRequest r;
  r.size_max = 0.1;
  r.face_quads = {{1, 1e6}};
  RequestEstimate e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 100.0 + 1e6, 1e-6);
  EXPECT_EQ(e.dominant, "--face-quads 1:1e+06");

  r = SizeRequest{};
  r.size_max = 0.1;
  r.face_sizes = {{0, 1e-3}};
  e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 1e6 + 100.0, 1e-3);

  // 4000 edges on the shared curve: each face has at least a quarter of its boundary's edges.
  r = SizeRequest{};
  r.size_max = 0.1;
  r.curve_edges = {{1, 4000}};
  e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 2 * 1000.0, 1e-9);
  EXPECT_EQ(e.dominant, "--curve-edges 1:4000");

  r.curve_edges.clear();
  r.curve_sizes = {{2, 1e-4}};
  e = estimate_request(two_squares(), r);
  EXPECT_NEAR(e.quads, 2500.0 + 100.0, 1e-6);
}

// A face's --face-quads replaces its share: a small prescription lowers the bound.
TEST(Limits, FaceQuadsReplaceTheShare) {
  SizeRequest r;
  r.size_max = 0.01;
  r.face_quads = {{0, 10}};
  EXPECT_NEAR(estimate_request(two_squares(), r).quads, 10000.0 + 10.0, 1e-6);
}

// Out-of-range inputs never crash nor give a finite wrong number.
TEST(Limits, ExtremeSizes) {
  SizeRequest r;
  r.size_max = 1e-300;
  EXPECT_TRUE(std::isinf(estimate_request(two_squares(), r).quads));
  r.size_max = 1e300;
  EXPECT_GE(estimate_request(two_squares(), r).quads, 0.0);
  r.size_max = std::numeric_limits<double>::quiet_NaN();
  r.face_quads = {{-1, 5}, {99, 5}, {0, -3}};
  r.curve_edges = {{1000, 8}};
  r.curve_sizes = {{0, 0.0}};
  const RequestEstimate e = estimate_request(two_squares(), r);
  EXPECT_FALSE(std::isnan(e.quads));
  EXPECT_EQ(estimate_request(ModelMeasures{}, SizeRequest{}).quads, 0.0);
}

TEST(Limits, RefusalsNameTheRequestAndTheEstimate) {
  RequestEstimate e;
  e.quads = 3e8;
  e.dominant = "the size cap";
  const MachineMemory big{1e15, 0};
  auto why = refuse_request(e, 2e8, 1, 1, big, "--size-factor 1e-05");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("--size-factor 1e-05 asks for at least 3e+08 quads"), std::string::npos)
      << *why;
  EXPECT_NE(why->find("--max-quads 2e+08"), std::string::npos) << *why;
  EXPECT_FALSE(refuse_request(e, 0, 1, 1, big, "x"));    // no bound, memory enough
  EXPECT_FALSE(refuse_request(e, 3e8, 1, 1, big, "x"));  // at the bound

  // Memory: rank 0 holds the whole mesh; the other ranks on this machine their share.
  const auto [root, other] = estimate_rank_memory(1e8, 4);
  EXPECT_GT(root, other);
  EXPECT_NEAR(root, 40e6 + 350 * 1e8, 1);
  const MachineMemory small{root + 3 * other - 1, 0};
  e.quads = 1e8;
  why = refuse_request(e, 0, 4, 4, small, "--size 0.1");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("of memory on this machine"), std::string::npos) << *why;
  EXPECT_FALSE(refuse_request(e, 0, 4, 1, small, "--size 0.1"));  // the others elsewhere
  // One process's address-space limit.
  why = refuse_request(e, 0, 1, 1, MachineMemory{0, 1e9}, "--size 0.1");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("ulimit -v"), std::string::npos) << *why;

  e.quads = std::numeric_limits<double>::infinity();
  why = refuse_request(e, 0, 1, 1, big, "--size 1e-300");
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("more quads than a double can count"), std::string::npos) << *why;
  e.dominant = "--face-quads 0:2e+09";
  e.quads = 2e9;
  why = refuse_request(e, 2e8, 1, 1, big, "--size 1");
  ASSERT_TRUE(why);
  EXPECT_EQ(why->find("--face-quads 0:2e+09 asks"), 0u) << *why;
  EXPECT_NE(why->find("ask for fewer"), std::string::npos) << *why;
}

TEST(Limits, MachineMemoryIsReadable) {
  const MachineMemory m = machine_memory();
  EXPECT_GT(m.node, 1e8);  // any machine that runs the tests has more than 100 MB
  EXPECT_GE(m.process, 0.0);
}

}  // namespace
}  // namespace qsmesh::cli
