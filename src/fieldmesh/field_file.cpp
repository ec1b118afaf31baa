// The user's cross-field file, the per-face method and the face-level entry of the pipeline.
#include "qsmesh/fieldmesh/field_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "internal.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::fieldmesh {

const GivenFaceField* GivenFields::find(LO f) const {
  const auto it = std::lower_bound(faces.begin(), faces.end(), f,
                                   [](const GivenFaceField& g, LO x) { return g.face < x; });
  return it != faces.end() && it->face == f ? &*it : nullptr;
}

const char* to_string(FaceMethod m) {
  switch (m) {
    case FaceMethod::Default:
      return "default";
    case FaceMethod::GivenField:
      return "given-field";
    case FaceMethod::Separatrix:
      return "separatrix";
  }
  return "?";
}

FaceMethod face_method(LO f, const GivenFields* given, bool separatrix) {
  if (given != nullptr && given->find(f) != nullptr) return FaceMethod::GivenField;
  return separatrix ? FaceMethod::Separatrix : FaceMethod::Default;
}

namespace {

constexpr const char* kHeader = "qsmesh-cross-field singular-points 1";

GivenFields read_points(std::istream& in, const std::string& path, LO num_faces) {
  GivenFields g;
  g.format = "singular-points";
  std::map<LO, GivenFaceField> faces;
  GivenFaceField* current = nullptr;
  std::string line;
  int number = 0;
  bool header = false;
  auto bad = [&](const std::string& what) {
    throw InputError("--cross-field: " + path + ", line " + std::to_string(number) + ": " + what);
  };
  while (std::getline(in, line)) {
    ++number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word)) continue;
    if (!header) {
      std::string joined = word, next;
      while (ls >> next) joined += " " + next;
      if (joined != kHeader) bad(std::string("expected the header '") + kHeader + "'");
      header = true;
      continue;
    }
    if (word == "face") {
      long long f = -1;
      if (!(ls >> f) || f < 0 || f >= num_faces)
        bad("'face ID' with ID in [0, " + std::to_string(num_faces) + ")");
      if (faces.count(static_cast<LO>(f)) != 0) bad("face " + std::to_string(f) + " given twice");
      current = &faces[static_cast<LO>(f)];
      current->face = static_cast<LO>(f);
    } else if (word == "point") {
      if (current == nullptr) bad("'point' before any 'face'");
      SingularPoint p;
      if (!(ls >> p.position.x >> p.position.y >> p.position.z >> p.d))
        bad("'point X Y Z D' expected (D: the index times 4, an integer)");
      if (p.d == 0 || p.d >= 4 || p.d < -8)
        bad("D must be a nonzero integer in [-8, 3] (index D/4)");
      current->points.push_back(p);
    } else {
      bad("unknown keyword '" + word + "' (face, point)");
    }
    std::string extra;
    if (ls >> extra) bad("unexpected '" + extra + "'");
  }
  if (!header) throw InputError("--cross-field: " + path + ": empty file");
  for (auto& [f, face] : faces) g.faces.push_back(std::move(face));
  return g;
}

// --- VTU (the arrays `qsmesh crossfield` writes) ---------------------------------------------

std::string attribute(const std::string& tag, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const auto at = tag.find(key);
  if (at == std::string::npos) return {};
  const auto end = tag.find('"', at + key.size());
  return end == std::string::npos ? std::string()
                                  : tag.substr(at + key.size(), end - at - key.size());
}

std::vector<unsigned char> base64(std::string_view s) {
  static const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned buffer = 0;
  int bits = 0;
  for (char ch : s) {
    if (ch == '=' || std::isspace(static_cast<unsigned char>(ch))) continue;
    const auto k = alphabet.find(ch);
    if (k == std::string::npos) throw InputError("bad base64 character");
    buffer = (buffer << 6) | static_cast<unsigned>(k);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buffer >> bits) & 0xFF));
    }
  }
  return out;
}

template <class T>
void append_values(const unsigned char* data, std::size_t bytes, std::vector<double>& out) {
  for (std::size_t i = 0; i + sizeof(T) <= bytes; i += sizeof(T)) {
    T v;
    std::memcpy(&v, data + i, sizeof(T));
    out.push_back(static_cast<double>(v));
  }
}

// Every DataArray of the file by name, as doubles.
std::map<std::string, std::vector<double>> data_arrays(const std::string& text) {
  std::map<std::string, std::vector<double>> arrays;
  std::size_t pos = 0;
  while ((pos = text.find("<DataArray", pos)) != std::string::npos) {
    const auto close = text.find('>', pos);
    const auto end = text.find("</DataArray>", close);
    if (close == std::string::npos || end == std::string::npos)
      throw InputError("unterminated DataArray");
    const std::string tag = text.substr(pos, close - pos);
    const std::string body = text.substr(close + 1, end - close - 1);
    const std::string type = attribute(tag, "type"), format = attribute(tag, "format");
    std::vector<double> values;
    if (format == "ascii") {
      std::istringstream in(body);
      double v;
      while (in >> v) values.push_back(v);
    } else if (format == "binary") {
      // An 8-byte header (the byte count) and the data, two base64 blocks.
      std::string compact;
      for (char ch : body)
        if (!std::isspace(static_cast<unsigned char>(ch))) compact += ch;
      if (compact.size() < 12) throw InputError("short binary DataArray");
      const auto head = base64(std::string_view(compact).substr(0, 12));
      std::uint64_t bytes = 0;
      std::memcpy(&bytes, head.data(), sizeof bytes);
      const auto data = base64(std::string_view(compact).substr(12));
      if (data.size() < bytes) throw InputError("binary DataArray shorter than its header");
      if (type == "Float64")
        append_values<double>(data.data(), bytes, values);
      else if (type == "Float32")
        append_values<float>(data.data(), bytes, values);
      else if (type == "Int64")
        append_values<std::int64_t>(data.data(), bytes, values);
      else if (type == "Int32")
        append_values<std::int32_t>(data.data(), bytes, values);
      else if (type == "UInt8")
        append_values<std::uint8_t>(data.data(), bytes, values);
      else
        throw InputError("DataArray type " + type + " not read");
    } else {
      throw InputError("DataArray format '" + format + "' not read (ascii or binary)");
    }
    arrays[attribute(tag, "Name")] = std::move(values);
    pos = end;
  }
  return arrays;
}

GivenFields read_vtu(const std::string& text, const std::string& path, LO num_faces) {
  GivenFields g;
  g.format = "crossfield-vtu";
  std::map<std::string, std::vector<double>> a;
  try {
    a = data_arrays(text);
  } catch (const InputError& e) {
    throw InputError("--cross-field: " + path + ": " + e.what());
  }
  for (const char* name :
       {"Points", "connectivity", "offsets", "types", "cad_face", "cross_u", "singularity_index"})
    if (a.count(name) == 0)
      throw InputError("--cross-field: " + path + ": no array '" + name +
                       "' (a VTU file written by `qsmesh crossfield -o` is expected)");
  const auto& xyz = a["Points"];
  const auto& conn = a["connectivity"];
  const auto& offsets = a["offsets"];
  const auto& types = a["types"];
  const auto& face = a["cad_face"];
  const auto& cu = a["cross_u"];
  const auto& index = a["singularity_index"];
  const std::size_t nc = types.size();
  if (offsets.size() != nc || face.size() != nc || cu.size() != 3 * nc || index.size() != nc)
    throw InputError("--cross-field: " + path + ": cell arrays of different lengths");
  std::map<LO, GivenFaceField> faces;
  std::size_t begin = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    const auto end = static_cast<std::size_t>(offsets[c]);
    if (end < begin || end > conn.size())
      throw InputError("--cross-field: " + path + ": bad offsets");
    const auto f = static_cast<LO>(face[c]);
    const Vec3 d{cu[3 * c], cu[3 * c + 1], cu[3 * c + 2]};
    if (types[c] == 5 && end - begin == 3 && norm(d) > 0) {
      if (f < 0 || f >= num_faces)
        throw InputError("--cross-field: " + path + ": face " + std::to_string(f) +
                         " is not a face of the model");
      Vec3 centre;
      for (std::size_t k = begin; k < end; ++k) {
        const auto v = static_cast<std::size_t>(conn[k]);
        if (3 * v + 2 >= xyz.size())
          throw InputError("--cross-field: " + path + ": bad connectivity");
        centre += Vec3{xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]} / 3.0;
      }
      GivenFaceField& gf = faces[f];
      gf.face = f;
      gf.sampled = true;
      gf.samples.positions.push_back(centre);
      gf.samples.directions.push_back(d);
    }
    if (types[c] == 1 && end - begin == 1 && index[c] != 0 && f >= 0 && f < num_faces) {
      const auto v = static_cast<std::size_t>(conn[begin]);
      if (3 * v + 2 >= xyz.size())
        throw InputError("--cross-field: " + path + ": bad connectivity");
      // Paper 000's index +1 is a valence-3 point, index 1/4 in paper 003's terms.
      faces[f].samples.singular.push_back(
          {{xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]}, static_cast<int>(index[c])});
    }
    begin = end;
  }
  for (auto& [f, ff] : faces)
    if (ff.sampled) g.faces.push_back(std::move(ff));
  return g;
}

}  // namespace

GivenFields read_cross_field_file(const std::string& path, LO num_faces) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("--cross-field: cannot read '" + path + "'");
  std::ostringstream all;
  all << in.rdbuf();
  const std::string text = all.str();
  if (text.find("<VTKFile") != std::string::npos) return read_vtu(text, path, num_faces);
  std::istringstream lines(text);
  return read_points(lines, path, num_faces);
}

std::vector<double> field_from_samples(const mesh::FaceMesh& tri, const Frame& frame,
                                       const FieldSamples& samples) {
  QSMESH_CHECK(!samples.positions.empty(), "face " << tri.face << ": no field sample");
  // Uniform grid over the samples for the nearest one.
  Box3 box;
  for (const auto& p : samples.positions) box.add(p);
  const double n = std::cbrt(static_cast<double>(samples.positions.size())) + 1;
  const double cell = std::max(box.diagonal() / n, 1e-12);
  auto key = [&](const Vec3& p) {
    return std::array<long, 3>{static_cast<long>(std::floor((p.x - box.lo.x) / cell)),
                               static_cast<long>(std::floor((p.y - box.lo.y) / cell)),
                               static_cast<long>(std::floor((p.z - box.lo.z) / cell))};
  };
  std::map<std::array<long, 3>, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < samples.positions.size(); ++i)
    grid[key(samples.positions[i])].push_back(i);
  std::vector<Vec3> dirs(tri.points.size());
  for (std::size_t v = 0; v < tri.points.size(); ++v) {
    const auto k = key(tri.points[v]);
    std::size_t best = 0;
    double best_d = 1e300;
    for (long r = 1; best_d == 1e300 || static_cast<double>(r - 1) * cell < std::sqrt(best_d);
         ++r) {
      for (long i = -r; i <= r; ++i)
        for (long j = -r; j <= r; ++j)
          for (long l = -r; l <= r; ++l) {
            const auto it = grid.find({k[0] + i, k[1] + j, k[2] + l});
            if (it == grid.end()) continue;
            for (std::size_t s : it->second) {
              const double d = norm2(samples.positions[s] - tri.points[v]);
              if (d < best_d) {
                best_d = d;
                best = s;
              }
            }
          }
      if (r > 1000) break;
    }
    dirs[v] = samples.directions[best];
  }
  std::vector<double> theta = field_from_directions(frame, dirs);
  std::vector<std::vector<LO>> nbr(tri.points.size());
  for (const auto& t : tri.triangles)
    for (int k = 0; k < 3; ++k) {
      nbr[t[k]].push_back(t[(k + 1) % 3]);
      nbr[t[(k + 1) % 3]].push_back(t[k]);
    }
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<double> next = theta;
    for (std::size_t v = 0; v < theta.size(); ++v) {
      if (tri.vclass[v].dim != 2 || nbr[v].empty()) continue;
      double c = std::cos(4 * theta[v]), sn = std::sin(4 * theta[v]);
      for (LO w : nbr[v]) {
        c += std::cos(4 * theta[w]);
        sn += std::sin(4 * theta[w]);
      }
      if (std::hypot(c, sn) > 1e-9) next[v] = std::atan2(sn, c) / 4;
    }
    theta = std::move(next);
  }
  return theta;
}

mesh::FaceMesh mesh_face_by_method(const cad::CadModel& model, LO f,
                                   std::span<const mesh::CurveMesh> curves, FaceMethod method,
                                   const GivenFaceField* given, const FieldSamples* own,
                                   const FieldMeshOptions& options, linalg::SolverLane* lane,
                                   FieldMeshReport* report) {
  FieldMeshReport local;
  FieldMeshReport& rep = report != nullptr ? *report : local;
  rep = FieldMeshReport{};
  rep.face = f;
  try {
    QSMESH_CHECK(method != FaceMethod::Default, "face " << f << ": no field method");
    QSMESH_CHECK(method != FaceMethod::GivenField || given != nullptr,
                 "face " << f << ": no given field");
    QSMESH_CHECK(method != FaceMethod::Separatrix || (own != nullptr && !own->positions.empty()),
                 "face " << f << ": the mesher's cross field is missing");
    double len = 0;
    int cnt = 0;
    for (const auto& loop : model.faces()[f].loops)
      for (const auto& use : loop.uses)
        for (std::size_t i = 1; i < curves[use.curve].points.size(); ++i, ++cnt)
          len += distance(curves[use.curve].points[i - 1], curves[use.curve].points[i]);
    QSMESH_CHECK(cnt > 0 && len > 0, "face " << f << ": no curve edge");
    background::BackgroundOptions bo;
    bo.sizes.size = 0.5 * len / cnt;
    background::FaceReport br;
    const mesh::FaceMesh tri = background::mesh_face_background(model, f, curves, bo, &br);
    QSMESH_CHECK(br.ok && !tri.triangles.empty(),
                 "face " << f << ": no triangulation: " << br.error);
    const auto surface = model.face_geometry(f);
    const Frame frame = face_frame(tri, *surface, lane);
    std::vector<double> theta;
    std::vector<SingularPoint> points;
    if (method == FaceMethod::GivenField && !given->sampled) {
      theta = field_from_points(tri, *surface, given->points);
      points = given->points;
    } else {
      theta =
          field_from_samples(tri, frame, method == FaceMethod::GivenField ? given->samples : *own);
    }
    return mesh_face_from_field(model, f, curves, tri, frame, theta, points, options, lane, &rep);
  } catch (const std::exception& e) {
    rep.ok = false;
    rep.stage = "field";
    rep.reason = e.what();
  }
  return {};
}

}  // namespace qsmesh::fieldmesh
