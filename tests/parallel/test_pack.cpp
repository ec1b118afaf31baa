#include <gtest/gtest.h>

#include "qsmesh/core/error.hpp"
#include "qsmesh/parallel/pipeline.hpp"

namespace qsmesh::parallel {
namespace {

TEST(Pack, RoundTripOfFaceMeshesAndReports) {
  mesh::FaceMesh a;
  a.face = 3;
  a.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5}};
  a.uv = {{0, 0}, {1, 0}, {0, 1}};
  a.vclass = {mesh::VertexClass{0, 7, kNoIndex, {0, 0}}, mesh::VertexClass{1, 2, 4, {0.25, 0}},
              mesh::VertexClass{2, 3, kNoIndex, {0, 1}}};
  a.triangles = {{0, 1, 2}};
  background::FaceReport ra;
  ra.face = 3;
  ra.ok = true;
  ra.fell_back = true;
  ra.error = "[background] face 3: refinement failed";
  ra.seconds = 0.5;
  mesh::FaceMesh b;
  b.face = 9;
  background::FaceReport rb;
  rb.face = 9;

  std::vector<char> buf;
  pack(a, ra, buf);
  pack(b, rb, buf);
  std::size_t pos = 0;
  mesh::FaceMesh a2, b2;
  background::FaceReport ra2, rb2;
  unpack(buf, pos, a2, ra2);
  unpack(buf, pos, b2, rb2);
  EXPECT_EQ(pos, buf.size());
  EXPECT_EQ(a2.face, 3);
  EXPECT_EQ(a2.points, a.points);
  EXPECT_EQ(a2.uv, a.uv);
  EXPECT_EQ(a2.triangles, a.triangles);
  EXPECT_EQ(a2.vclass[1].entity, 2);
  EXPECT_EQ(a2.vclass[1].index, 4);
  EXPECT_EQ(ra2.error, ra.error);
  EXPECT_TRUE(ra2.fell_back);
  EXPECT_EQ(b2.face, 9);
  EXPECT_TRUE(b2.points.empty());
  EXPECT_FALSE(rb2.ok);
  // A truncated buffer is an error, not a crash.
  buf.resize(buf.size() - 3);
  pos = 0;
  unpack(buf, pos, a2, ra2);
  EXPECT_THROW(unpack(buf, pos, b2, rb2), Error);
}

TEST(Pack, RoundTripOfQuadReportsAndSizes) {
  quad::UnstructuredReport r;
  r.ok = false;
  r.fell_back = true;
  r.error = "[unstructured] face 8: a quad is folded";
  r.sicn_min = -0.25;
  r.quads = 1234;
  r.frontal = true;
  r.frontal_points = 77;
  sizemap::FaceSizes sz;
  sz.s = {1, 2, 3};
  sz.s_min = {0.5, 2, 3};
  std::vector<char> buf;
  pack(r, buf);
  pack(sz, buf);
  std::size_t pos = 0;
  quad::UnstructuredReport r2;
  sizemap::FaceSizes sz2;
  unpack(buf, pos, r2);
  unpack(buf, pos, sz2);
  EXPECT_EQ(pos, buf.size());
  EXPECT_FALSE(r2.ok);
  EXPECT_TRUE(r2.fell_back);
  EXPECT_EQ(r2.error, r.error);
  EXPECT_EQ(r2.sicn_min, -0.25);
  EXPECT_EQ(r2.quads, 1234);
  EXPECT_TRUE(r2.frontal);
  EXPECT_EQ(r2.frontal_points, 77);
  EXPECT_EQ(sz2.s, sz.s);
  EXPECT_EQ(sz2.s_min, sz.s_min);
  EXPECT_TRUE(sz2.s_cf.empty());
}

}  // namespace
}  // namespace qsmesh::parallel
