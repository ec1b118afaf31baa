// Curves across which the surface is smooth (G1 within an angle tolerance): where two faces meet
// without a crease. Used by the groups of paper 004 (holomorphic::smooth_face_groups), which mesh
// such faces as one surface, and by the coarse block layout of paper 002 (layout::
// build_coarse_layout), whose blocks may cross such curves, as the paper's blocks cross the
// construction curves of an aircraft skin.
#pragma once

#include "qsmesh/cad/model.hpp"

namespace qsmesh::cad {

/// Whether the surface is smooth across curve c: exactly two distinct faces use it, and their
/// normals (each oriented as its face) differ by at most `max_normal_angle_deg` degrees at
/// `samples` points of the curve, at equal steps of its parameter, ends excluded (poles, where a
/// face has no normal, are skipped; at least one point must be compared). The orientation of each
/// face in the shell is read from the direction it traverses c (opposite in two faces of a
/// consistently oriented shell; the same when one of them is flipped, which is then allowed for).
/// Degenerate curves, seams (one face) and non-manifold curves (three faces or more) are not
/// smooth. A fillet's tangent curves differ by 0 degrees, a cylinder cut by a plane by 90.
[[nodiscard]] bool smooth_across(const CadModel& model, LO c, double max_normal_angle_deg,
                                 int samples = 9);

}  // namespace qsmesh::cad
