// Private data of CadModel: the OpenCASCADE shapes behind the ids. Never included outside src/cad.
#pragma once

#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <memory>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"

namespace qsmesh::cad {

struct CadModel::Impl {
  TopoDS_Shape shape;
  TopTools_IndexedMapOfShape vertex_map, edge_map, face_map;  ///< ids are map index - 1
  std::vector<TopoDS_Edge> edges;                             ///< per curve, oriented FORWARD
  std::vector<TopoDS_Face> faces;  ///< per face, oriented FORWARD (loops are expressed on it)
  /// Per face, per loop, per use: the edge oriented as traversed in that loop of the FORWARD face
  /// (its pcurve on the forward face is the image of that use; the two uses of a seam differ).
  std::vector<std::vector<std::vector<TopoDS_Edge>>> loop_edges;
};

/// Builds the topology of a shape (friend of CadModel).
class ModelBuilder {
 public:
  static CadModel build(const TopoDS_Shape& shape, std::string source,
                        const MeasureItems& measure_faces);
};

std::unique_ptr<CurveGeometry> make_curve_geometry(const CadModel::Impl& impl, const Curve& curve,
                                                   const Vec3& corner_point, LO c);
std::unique_ptr<FaceGeometry> make_face_geometry(const CadModel::Impl& impl, const Face& face, LO f,
                                                 bool with_classifier);

}  // namespace qsmesh::cad
