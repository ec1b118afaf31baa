// Helpers of the cad tests: writing OpenCASCADE shapes to files, loop geometry in (u, v).
#pragma once

#include <gtest/gtest.h>

#include <BRepTools.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS_Shape.hxx>
#include <string>

#include "qsmesh/cad/model.hpp"
#include "tmp_dir.hpp"

namespace qsmesh::cad::test {

inline std::string tmp_path(const std::string& name) {
  return qsmesh::test::tmp_dir() + "/" + name;
}

inline void write_brep(const TopoDS_Shape& s, const std::string& path) {
  ASSERT_TRUE(BRepTools::Write(s, path.c_str()));
}

inline void write_step(const TopoDS_Shape& s, const std::string& path) {
  STEPControl_Writer w;
  ASSERT_EQ(w.Transfer(s, STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(w.Write(path.c_str()), IFSelect_RetDone);
}

inline void write_iges(const TopoDS_Shape& s, const std::string& path) {
  IGESControl_Controller::Init();
  IGESControl_Writer w("MM", 1);  // BRep mode: shared topology
  ASSERT_TRUE(w.AddShape(s));
  w.ComputeModel();
  ASSERT_TRUE(w.Write(path.c_str()));
}

/// Writes a shape as BREP and loads it back.
inline CadModel round_trip(const TopoDS_Shape& s, const std::string& name) {
  const std::string path = tmp_path(name + ".brep");
  write_brep(s, path);
  return load_cad(path);
}

/// Points of the (u, v) image of a loop, sampled along each use in its traversal direction.
inline std::vector<Vec2> loop_polygon(const CadModel& m, const FaceGeometry& g, LO f, LO l,
                                      int samples = 32) {
  std::vector<Vec2> poly;
  const Loop& loop = m.faces()[f].loops[l];
  for (LO k = 0; k < static_cast<LO>(loop.uses.size()); ++k) {
    const CurveUse& u = loop.uses[k];
    const Curve& c = m.curves()[u.curve];
    for (int i = 0; i < samples; ++i) {
      const double s = static_cast<double>(i) / samples;
      const double t = u.reversed ? c.t1 + s * (c.t0 - c.t1) : c.t0 + s * (c.t1 - c.t0);
      poly.push_back(g.boundary_uv(l, k, t));
    }
  }
  return poly;
}

/// Signed area of a closed polygon (counterclockwise positive).
inline double signed_area(const std::vector<Vec2>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += cross(p[i], p[(i + 1) % p.size()]);
  return 0.5 * a;
}

/// Checks that consecutive uses of every loop of every face share a corner.
inline void expect_closed_loops(const CadModel& m) {
  for (LO f = 0; f < m.num_faces(); ++f) {
    const Face& face = m.faces()[f];
    EXPECT_TRUE(face.loops_closed) << "face " << f;
    for (const Loop& l : face.loops) {
      const std::size_t n = l.uses.size();
      for (std::size_t k = 0; k < n; ++k) {
        const CurveUse& a = l.uses[k];
        const CurveUse& b = l.uses[(k + 1) % n];
        EXPECT_EQ(m.curves()[a.curve].corners[a.reversed ? 0 : 1],
                  m.curves()[b.curve].corners[b.reversed ? 1 : 0])
            << "face " << f << " use " << k;
      }
    }
  }
}

}  // namespace qsmesh::cad::test
